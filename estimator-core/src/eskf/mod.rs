//! On-manifold error-state Kalman filter (work in progress).
