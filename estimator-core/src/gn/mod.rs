//! Fixed-size Gauss-Newton / Levenberg-Marquardt on manifolds (work in progress).
