//! The ball booking of TeamChaos (ThinkingCap/TeamChaos report §3.3): `bookBall` asks the teammates to book the
//! ball for this robot, `releaseBookedBall` gives it back, `haveBookedBall` says whether it is
//! booked. The seed implements it with a distributed mutual exclusion (Agüero et al., 2006b,
//! not retrieved); this is one built for robots that talk over a lossy, delaying network and
//! may fall silent. Two robots never hold the booking at once while they can hear each other.
//!
//! Every robot sends a [`BookingReport`] with each of its team reports: its **claim** (when
//! it began wanting the ball), the claim it **grants** (supports), and an **echo** of the
//! latest report it heard from each teammate.
//!
//! - **Grants.** A robot grants the earliest claim it knows of among its own and those of
//!   the teammates it has heard within [`BookingParams::silent`] (ties: the lower number),
//!   unless a teammate grants its own claim: that one may be holding, and is supported
//!   first. A grant is sticky. It moves to a better claim only when the claim it grants
//!   cannot be holding: it is the robot's own and it does not hold, or its claimant's latest
//!   report shows it supporting another claim. A grant falls when its claim is withdrawn or
//!   its claimant falls silent. So a holder keeps the booking until it lets go.
//! - **Holding.** A robot holds the booking while it claims, grants its own claim, and the
//!   latest report of every teammate heard within `silent` grants its claim too. Each such
//!   report echoes one of its own reports, stamped `s` on its own clock. That teammate will
//!   not think it silent, and so will not grant another claim, before `s + silent`. The
//!   robot's hold therefore lapses at the earliest `s + silent` (less
//!   [`BookingParams::margin`] for clocks that run at slightly different rates) unless
//!   fresher echoes come.
//! - **Why two never hold at once.** Suppose robots A and B hear each other. A holding means
//!   that A grants itself and that B's latest report grants A. For B to hold, B needs a
//!   report from A granting B. A sends one only after moving its grant away from itself,
//!   which it does only when it does not hold. A report from B that A has not yet received
//!   cannot help B either: B's grant moves from A only when A's claim is withdrawn (A
//!   withdraws its claim, and so its hold, first) or when A has been silent for `silent` (A's
//!   lease from B has run out by then). Two robots that have heard nothing from each other
//!   for `silent` are cut off: each books for itself alone ([`BallBooking::alone`]), as a
//!   SCARE robot that has lost its team allocates for itself.
//! - **Timeouts.** A claim lapses [`BookingParams::lapse`] after the last `bookBall` (a
//!   behavior that forgot to release does not block its team). A silent holder's booking
//!   passes to the next claim `silent` after its last report was heard.
//!
//! Times are seconds on the robot's own clock; only differences of one clock are compared.
//!
//! ```
//! use mrt_team::booking::{BallBooking, BookingParams};
//!
//! let (mut a, mut b) = (BallBooking::new(1, BookingParams::default()), BallBooking::new(2, BookingParams::default()));
//! // Both want the ball; robot 1 asked first.
//! a.want(0.0, true);
//! b.want(0.05, true);
//! for k in 1..5 {
//!     let now = 0.1 * f64::from(k);
//!     a.update(now);
//!     b.update(now);
//!     let (ra, rb) = (a.report(now), b.report(now));
//!     a.receive(now, 2, &rb);
//!     b.receive(now, 1, &ra);
//! }
//! assert!(a.holds(0.45) && !b.holds(0.45));
//! // Robot 1 is done with the ball: robot 2 gets it a few reports later.
//! a.want(0.5, false);
//! for k in 5..9 {
//!     let now = 0.1 * f64::from(k);
//!     a.update(now);
//!     b.update(now);
//!     let (ra, rb) = (a.report(now), b.report(now));
//!     a.receive(now, 2, &rb);
//!     b.receive(now, 1, &ra);
//! }
//! assert!(!a.holds(0.85) && b.holds(0.85));
//! ```

use mrt_msgs::BookingReport;
use std::cmp::Ordering;
use std::collections::BTreeMap;

/// The booking's timing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BookingParams {
    /// A teammate not heard for this long is silent: its claim and grant no longer count, s.
    pub silent: f64,
    /// A claim not affirmed by `bookBall` for this long lapses, s.
    pub lapse: f64,
    /// A hold ends this much before its lease, for clocks that drift, s.
    pub margin: f64,
}

impl Default for BookingParams {
    /// Silent after 1 s (ten reports at 10 Hz), a claim lapses after 5 s, a 50 ms margin.
    fn default() -> Self {
        BookingParams { silent: 1.0, lapse: 5.0, margin: 0.05 }
    }
}

/// The most teammates one robot keeps track of: reports from more numbers are dropped.
pub const MAX_TEAMMATES: usize = 32;

/// What a robot keeps of a teammate's latest report.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Heard {
    /// When it came, on this robot's clock.
    at: f64,
    /// Its stamp, on the teammate's clock.
    stamp: f64,
    claim: Option<f64>,
    grant: Option<(u32, f64)>,
    /// The stamp of this robot's report it echoes.
    echo: Option<f64>,
}

/// One robot's side of the ball booking (module doc).
#[derive(Clone, Debug)]
pub struct BallBooking {
    me: u32,
    params: BookingParams,
    claim: Option<f64>,
    affirmed: f64,
    grant: Option<(u32, f64)>,
    heard: BTreeMap<u32, Heard>,
    dropped: u64,
}

/// Orders claims `(claimant, time)`: the earlier first, then the lower number.
fn better(a: (u32, f64), b: (u32, f64)) -> bool {
    a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)) == Ordering::Less
}

impl BallBooking {
    /// Robot `me`'s booking, claiming nothing.
    pub fn new(me: u32, params: BookingParams) -> BallBooking {
        BallBooking {
            me,
            params,
            claim: None,
            affirmed: f64::NEG_INFINITY,
            grant: None,
            heard: BTreeMap::new(),
            dropped: 0,
        }
    }

    /// `bookBall` (`yes`) or `releaseBookedBall` at `now`. Asking again affirms the claim
    /// and keeps its place; releasing drops the claim and any hold at once.
    pub fn want(&mut self, now: f64, yes: bool) {
        if !now.is_finite() {
            return;
        }
        if yes {
            self.claim.get_or_insert(now);
            self.affirmed = now;
        } else {
            self.claim = None;
            if self.grant.is_some_and(|g| g.0 == self.me) {
                self.grant = None;
            }
        }
    }

    /// Teammate `from`'s report, received at `now`. Reports older than the latest one heard
    /// from it (late, reordered or repeated) and reports with odd times are dropped and
    /// counted ([`BallBooking::dropped`]), as are reports from beyond [`MAX_TEAMMATES`].
    pub fn receive(&mut self, now: f64, from: u32, report: &BookingReport) {
        let finite = |v: Option<f64>| v.is_none_or(f64::is_finite);
        let sane = now.is_finite()
            && report.stamp.is_finite()
            && finite(report.claim)
            && finite(report.grant.map(|g| g.1));
        let full = !self.heard.contains_key(&from) && self.heard.len() >= MAX_TEAMMATES;
        let stale = self.heard.get(&from).is_some_and(|h| report.stamp <= h.stamp);
        if from == self.me || !sane || full || stale {
            self.dropped += 1;
            return;
        }
        let echo = report.echo.iter().find(|e| e.0 == self.me).map(|e| e.1);
        let heard =
            Heard { at: now, stamp: report.stamp, claim: report.claim, grant: report.grant, echo };
        self.heard.insert(from, heard);
    }

    /// Whether the teammate whose latest report is `h` has been heard within `silent`.
    fn alive(&self, h: &Heard, now: f64) -> bool {
        now - h.at <= self.params.silent
    }

    /// Whether claim `(who, time)` still stands, as far as this robot knows.
    fn stands(&self, (who, time): (u32, f64), now: f64) -> bool {
        if who == self.me {
            return self.claim == Some(time);
        }
        self.heard.get(&who).is_some_and(|h| self.alive(h, now) && h.claim == Some(time))
    }

    /// Lapses an unaffirmed claim and moves the grant (module doc). Call once a cycle,
    /// after the cycle's reports are received and before [`BallBooking::report`].
    pub fn update(&mut self, now: f64) {
        if !now.is_finite() {
            return;
        }
        if self.claim.is_some() && now - self.affirmed > self.params.lapse {
            self.want(now, false);
        }
        if self.grant.is_some_and(|g| !self.stands(g, now)) {
            self.grant = None;
        }
        let mine = self.claim.map(|c| (self.me, c));
        let theirs = self
            .heard
            .iter()
            .filter(|(_, h)| self.alive(h, now))
            .filter_map(|(&j, h)| h.claim.map(|c| (j, c)));
        let pick = |a: (u32, f64), b: (u32, f64)| if better(b, a) { b } else { a };
        let best = mine.into_iter().chain(theirs).reduce(pick);
        // A teammate that grants its own claim may be holding: a robot with no grant yet
        // supports it rather than a better claim, so that a holder is not preempted by a
        // claim that only looks earlier (a clock behind, a report that came late).
        let holding = self
            .heard
            .iter()
            .filter(|(_, h)| self.alive(h, now))
            .filter_map(|(&j, h)| h.claim.map(|c| (j, c)).filter(|&c| h.grant == Some(c)))
            .reduce(pick);
        self.grant = match (self.grant, best) {
            (None, best) => holding.or(best),
            (Some(g), Some(b)) if better(b, g) && self.may_leave(g, now) => Some(b),
            (g, _) => g,
        };
    }

    /// Whether the grant to claim `g` may move to a better claim: the claim cannot be
    /// holding.
    fn may_leave(&self, g: (u32, f64), now: f64) -> bool {
        if g.0 == self.me {
            return !self.holds(now);
        }
        // Its claimant's latest report supports another claim: it does not hold.
        self.heard.get(&g.0).is_some_and(|h| h.grant != Some(g))
    }

    /// Whether this robot holds the booking at `now` (`haveBookedBall`).
    pub fn holds(&self, now: f64) -> bool {
        let Some(c) = self.claim else { return false };
        let own = (self.me, c);
        if self.grant != Some(own) {
            return false;
        }
        let margin = self.params.margin;
        self.heard.values().filter(|h| self.alive(h, now)).all(|h| {
            h.grant == Some(own) && h.echo.is_some_and(|s| now < s + self.params.silent - margin)
        })
    }

    /// Whether teammate `j` has been heard within [`BookingParams::silent`] of `now`.
    pub fn hears(&self, j: u32, now: f64) -> bool {
        self.heard.get(&j).is_some_and(|h| self.alive(h, now))
    }

    /// Whether no teammate has been heard within [`BookingParams::silent`]: the robot books
    /// for itself alone.
    pub fn alone(&self, now: f64) -> bool {
        !self.heard.values().any(|h| self.alive(h, now))
    }

    /// The report to send at `now`.
    pub fn report(&self, now: f64) -> BookingReport {
        BookingReport {
            stamp: now,
            claim: self.claim,
            grant: self.grant,
            echo: self.heard.iter().map(|(&j, h)| (j, h.stamp)).collect(),
        }
    }

    /// Whether this robot wants the ball (has claimed it and not released it).
    pub fn claims(&self) -> bool {
        self.claim.is_some()
    }

    /// Reports dropped: late, repeated, from itself, with odd times, or from too many
    /// teammates.
    pub fn dropped(&self) -> u64 {
        self.dropped
    }
}
