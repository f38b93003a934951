//! Sample timestamps: 64-bit nanoseconds, strictly increasing per sensor.

use super::error::NavError;

/// What a new timestamp means against the previous one.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Tick {
    /// The first sample.
    First,
    /// An interval, ns, within the configured maximum.
    Step(u32),
    /// An interval above the configured maximum: the data in between are missing.
    Gap,
}

/// The last accepted timestamp of one sensor.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub(crate) struct Clock {
    last: Option<u64>,
}

impl Clock {
    /// Classifies `t_ns` against the last accepted timestamp (nothing is changed).
    ///
    /// # Errors
    /// [`NavError::TimeNotIncreasing`] for `t_ns ≤` the last one.
    pub(crate) fn tick(&self, t_ns: u64, max_step_ns: u32) -> Result<Tick, NavError> {
        match self.last {
            None => Ok(Tick::First),
            Some(last) if t_ns <= last => Err(NavError::TimeNotIncreasing),
            Some(last) => match u32::try_from(t_ns - last) {
                Ok(step) if step <= max_step_ns => Ok(Tick::Step(step)),
                _ => Ok(Tick::Gap),
            },
        }
    }

    /// The last accepted timestamp.
    pub(crate) fn last(&self) -> Option<u64> {
        self.last
    }

    /// Accepts `t_ns`.
    pub(crate) fn set(&mut self, t_ns: u64) {
        self.last = Some(t_ns);
    }
}
