//! Time for DCDT: a [`Time`] stamp and the [`Clock`] every Agora reads it from.
//!
//! The MRT manual stamps each message with its creation time (`DCDT_TIME ReadCreationTime()`,
//! §3.3.3). MRT reads that time through a [`Clock`] so the same Members run on a robot
//! ([`WallClock`]) and in the simulator ([`SimClock`], moved forward only by whoever owns it).

use serde::{Deserialize, Serialize};
use std::fmt;
use std::ops::{Add, Sub};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::Duration;

/// A point in time, in nanoseconds since the clock's origin (the start of the run).
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize,
)]
pub struct Time(pub u64);

/// [`Time`]'s nanoseconds per millisecond.
const NS_PER_MS: u64 = 1_000_000;

/// [`Time`]'s nanoseconds per microsecond.
const NS_PER_US: u64 = 1_000;

impl Time {
    /// The clock's origin.
    pub const ZERO: Time = Time(0);

    /// A time `ms` milliseconds after the origin.
    pub const fn from_millis(ms: u64) -> Time {
        Time(ms * NS_PER_MS)
    }

    /// A time `us` microseconds after the origin.
    pub const fn from_micros(us: u64) -> Time {
        Time(us * NS_PER_US)
    }

    /// A time `s` seconds after the origin (negative or NaN clamps to zero).
    pub fn from_secs_f64(s: f64) -> Time {
        if s.is_finite() && s > 0.0 {
            Time((s * 1e9).round() as u64)
        } else {
            Time::ZERO
        }
    }

    /// Nanoseconds since the origin.
    pub const fn as_nanos(self) -> u64 {
        self.0
    }

    /// Seconds since the origin.
    pub fn as_secs_f64(self) -> f64 {
        self.0 as f64 * 1e-9
    }

    /// Time elapsed since the origin, as a [`Duration`].
    pub const fn since_origin(self) -> Duration {
        Duration::from_nanos(self.0)
    }

    /// `self - earlier`, or zero when `earlier` is later.
    pub fn saturating_since(self, earlier: Time) -> Duration {
        Duration::from_nanos(self.0.saturating_sub(earlier.0))
    }
}

impl Add<Duration> for Time {
    type Output = Time;
    fn add(self, d: Duration) -> Time {
        Time(self.0.saturating_add(u64::try_from(d.as_nanos()).unwrap_or(u64::MAX)))
    }
}

impl Sub<Time> for Time {
    type Output = Duration;
    /// Saturating: an earlier minus a later time is zero.
    fn sub(self, rhs: Time) -> Duration {
        self.saturating_since(rhs)
    }
}

impl fmt::Display for Time {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:.6}s", self.as_secs_f64())
    }
}

/// A source of time. All of DCDT reads time only through this trait.
pub trait Clock: Send + Sync + fmt::Debug {
    /// The current time.
    fn now(&self) -> Time;

    /// `true` when time only moves when somebody advances it (a [`SimClock`]). Executors use
    /// this to refuse mixing real-time scheduling with a simulated clock by mistake.
    fn is_simulated(&self) -> bool {
        false
    }
}

/// A clock shared by an Agora and everything in it.
pub type SharedClock = Arc<dyn Clock>;

/// Real, monotonic time since the clock was created.
///
/// Read through `quanta` (the CPU's invariant time-stamp counter, calibrated against the OS
/// clock, or the OS clock where there is no reliable TSC): a few nanoseconds per reading,
/// where `std::time::Instant` costs a `clock_gettime` call. Every DCDT message is stamped
/// with its creation time, so this is on the hot path.
#[derive(Debug, Clone)]
pub struct WallClock {
    clock: quanta::Clock,
    origin: quanta::Instant,
}

impl WallClock {
    /// A wall clock whose origin is now.
    pub fn new() -> Self {
        let clock = quanta::Clock::new();
        let origin = clock.now();
        Self { clock, origin }
    }
}

impl Default for WallClock {
    fn default() -> Self {
        Self::new()
    }
}

impl Clock for WallClock {
    fn now(&self) -> Time {
        let elapsed = self.clock.now().saturating_duration_since(self.origin);
        Time(u64::try_from(elapsed.as_nanos()).unwrap_or(u64::MAX))
    }
}

/// A simulated clock: it stands still until [`advance`](SimClock::advance) or
/// [`set`](SimClock::set) moves it. Clones share the same time.
#[derive(Debug, Clone, Default)]
pub struct SimClock {
    nanos: Arc<AtomicU64>,
}

impl SimClock {
    /// A simulated clock at [`Time::ZERO`].
    pub fn new() -> Self {
        Self::default()
    }

    /// Moves time forward by `d` and returns the new time.
    pub fn advance(&self, d: Duration) -> Time {
        let d = u64::try_from(d.as_nanos()).unwrap_or(u64::MAX);
        let before = self.nanos.fetch_add(d, Ordering::AcqRel);
        Time(before.saturating_add(d))
    }

    /// Sets the time. Time never goes backwards: an earlier `t` is ignored.
    pub fn set(&self, t: Time) {
        self.nanos.fetch_max(t.0, Ordering::AcqRel);
    }
}

impl Clock for SimClock {
    fn now(&self) -> Time {
        Time(self.nanos.load(Ordering::Acquire))
    }

    fn is_simulated(&self) -> bool {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sim_clock_moves_only_when_advanced_and_clones_share_time() {
        let c = SimClock::new();
        let c2 = c.clone();
        assert_eq!(c.now(), Time::ZERO);
        assert_eq!(c.advance(Duration::from_millis(5)), Time::from_millis(5));
        assert_eq!(c2.now(), Time::from_millis(5));
        c2.set(Time::from_millis(3)); // never backwards
        assert_eq!(c.now(), Time::from_millis(5));
        c2.set(Time::from_millis(9));
        assert_eq!(c.now(), Time::from_millis(9));
        assert!(c.is_simulated());
    }

    #[test]
    fn wall_clock_is_monotonic() {
        let c = WallClock::new();
        let a = c.now();
        let b = c.now();
        assert!(b >= a);
        assert!(!c.is_simulated());
    }

    #[test]
    fn time_arithmetic_saturates() {
        let t = Time::from_millis(10);
        assert_eq!(t + Duration::from_millis(5), Time::from_millis(15));
        assert_eq!(Time::from_millis(15) - t, Duration::from_millis(5));
        assert_eq!(t - Time::from_millis(15), Duration::ZERO);
        assert_eq!(Time::from_secs_f64(1.5), Time(1_500_000_000));
        assert_eq!(Time::from_secs_f64(-1.0), Time::ZERO);
        assert_eq!(Time::from_secs_f64(f64::NAN), Time::ZERO);
        assert_eq!(Time::from_micros(3).as_nanos(), 3000);
        assert_eq!(Time(u64::MAX) + Duration::from_secs(1), Time(u64::MAX));
        assert_eq!(Time::from_millis(1500).to_string(), "1.500000s");
    }
}
