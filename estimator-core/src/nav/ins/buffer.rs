//! Fixed-capacity storage of the delayed-fusion horizon: the IMU intervals the filter has not
//! yet integrated, and the measurements it has not yet fused.

use super::window::Interval;
use crate::kernels::larger;
use crate::Real;
use nalgebra::Vector3;

/// A first-in first-out ring of at most `H` IMU intervals.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct ImuRing<T: Real, const H: usize> {
    items: [Interval<T>; H],
    head: usize,
    len: usize,
}

impl<T: Real, const H: usize> ImuRing<T, H> {
    pub(crate) fn new() -> Self {
        let zero = Interval {
            t_ns: 0,
            gyro: Vector3::zeros(),
            accel: Vector3::zeros(),
            dt: T::zero(),
        };
        Self {
            items: [zero; H],
            head: 0,
            len: 0,
        }
    }

    pub(crate) fn len(&self) -> usize {
        self.len
    }

    pub(crate) fn is_full(&self) -> bool {
        self.len >= H
    }

    /// The oldest interval.
    pub(crate) fn front(&self) -> Option<&Interval<T>> {
        if self.len == 0 {
            None
        } else {
            self.items.get(self.head)
        }
    }

    /// Appends at the end; `false` (and nothing stored) when full.
    pub(crate) fn push(&mut self, item: Interval<T>) -> bool {
        if self.len >= H {
            return false;
        }
        let at = (self.head + self.len) % H;
        match self.items.get_mut(at) {
            Some(slot) => {
                *slot = item;
                self.len += 1;
                true
            }
            None => false,
        }
    }

    /// Removes and returns the oldest interval.
    pub(crate) fn pop(&mut self) -> Option<Interval<T>> {
        let item = *self.front()?;
        self.head = (self.head + 1) % H;
        self.len -= 1;
        Some(item)
    }

    pub(crate) fn clear(&mut self) {
        self.head = 0;
        self.len = 0;
    }
}

/// A GNSS position's 1σ: east and north (`horizontal`), and up, m.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct FixSigma<T: Real> {
    pub horizontal: T,
    pub up: T,
}

impl<T: Real> FixSigma<T> {
    /// `[σ_h, σ_h, σ_up]`, the 1σ of each world axis.
    pub(crate) fn per_axis(&self) -> Vector3<T> {
        Vector3::new(self.horizontal, self.horizontal, self.up)
    }

    /// The larger of the two: a bound on the 1σ of any direction.
    pub(crate) fn largest(&self) -> T {
        larger(self.horizontal, self.up)
    }
}

/// A measurement waiting for the filter to reach its time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Aid<T: Real> {
    /// A GNSS antenna position, world frame, with its horizontal and vertical 1σ.
    Gnss(Vector3<T>, FixSigma<T>),
    /// A GNSS antenna velocity, world frame, with its 1σ: the second half of a fix, stamped
    /// like its position and fused after it (in the next call: one update per call).
    GnssVelocity(Vector3<T>, T),
    /// A magnetometer sample, body frame.
    Magnetometer(Vector3<T>),
    /// A barometric altitude, m.
    Barometer(T),
}

impl<T: Real> Aid<T> {
    /// The order among measurements stamped at the same time (fusion order is then fixed,
    /// whatever the order of arrival).
    fn rank(&self) -> u8 {
        match self {
            Self::Gnss(..) => 0,
            Self::GnssVelocity(..) => 1,
            Self::Magnetometer(_) => 2,
            Self::Barometer(_) => 3,
        }
    }
}

/// A measurement and its time of validity, ns.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Queued<T: Real> {
    pub t_ns: u64,
    pub aid: Aid<T>,
}

impl<T: Real> Queued<T> {
    fn key(&self) -> (u64, u8) {
        (self.t_ns, self.aid.rank())
    }
}

/// At most `Q` measurements, taken out in time order.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct AidQueue<T: Real, const Q: usize> {
    items: [Option<Queued<T>>; Q],
    /// The earliest time among `items` (so that the common call, nothing due, reads one
    /// number instead of scanning the queue).
    earliest: Option<u64>,
}

/// Why a measurement could not be queued.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum QueueError {
    Full,
    /// One of the same kind with the same time is already waiting.
    Duplicate,
}

impl<T: Real, const Q: usize> AidQueue<T, Q> {
    pub(crate) fn new() -> Self {
        Self {
            items: [None; Q],
            earliest: None,
        }
    }

    /// Checks that `item` can be queued (nothing is changed).
    pub(crate) fn check(&self, item: &Queued<T>) -> Result<(), QueueError> {
        if self.items.iter().flatten().any(|q| q.key() == item.key()) {
            return Err(QueueError::Duplicate);
        }
        if self.items.iter().all(Option::is_some) {
            return Err(QueueError::Full);
        }
        Ok(())
    }

    /// Queues `item` after [`AidQueue::check`].
    pub(crate) fn insert(&mut self, item: Queued<T>) -> Result<(), QueueError> {
        self.check(&item)?;
        match self.items.iter_mut().find(|q| q.is_none()) {
            Some(slot) => {
                *slot = Some(item);
                self.earliest = Some(self.earliest.map_or(item.t_ns, |e| e.min(item.t_ns)));
                Ok(())
            }
            None => Err(QueueError::Full),
        }
    }

    /// The number of free places.
    pub(crate) fn free(&self) -> usize {
        self.items.iter().filter(|q| q.is_none()).count()
    }

    /// Removes and returns the GNSS velocity stamped `t_ns`, if one is waiting.
    pub(crate) fn take_velocity_at(&mut self, t_ns: u64) -> Option<(Vector3<T>, T)> {
        let slot = self.items.iter_mut().find(|q| {
            q.is_some_and(|q| q.t_ns == t_ns && matches!(q.aid, Aid::GnssVelocity(..)))
        })?;
        let taken = slot.take();
        self.earliest = self.items.iter().flatten().map(|q| q.t_ns).min();
        match taken?.aid {
            Aid::GnssVelocity(v, sigma) => Some((v, sigma)),
            _ => None,
        }
    }

    /// Removes and returns the earliest measurement stamped at or before `t_ns`.
    pub(crate) fn take_due(&mut self, t_ns: u64) -> Option<Queued<T>> {
        if self.earliest.is_none_or(|e| e > t_ns) {
            return None;
        }
        let taken = self
            .items
            .iter_mut()
            .filter(|q| q.is_some_and(|q| q.t_ns <= t_ns))
            .min_by_key(|q| q.map(|q| q.key()))
            .and_then(Option::take);
        self.earliest = self.items.iter().flatten().map(|q| q.t_ns).min();
        taken
    }

    pub(crate) fn clear(&mut self) {
        self.items = [None; Q];
        self.earliest = None;
    }
}
