//! The world-state Member: the robot's beliefs, its teammates' reports, roles and SCARE.

use super::*;

/// A team ball of at least this quality is known to the role allocation (the Lua players'
/// `ballKnown`).
const BALL_KNOWN: f64 = 0.2;

/// The world-state Member of one robot: odometry and camera frames into its [`WorldModel`],
/// teammates from their reports over the bus; publishes the [`WorldSnapshot`] and its own
/// [`MateReport`].
pub(super) struct WorldState {
    pub(super) robot: usize,
    pub(super) keeper: bool,
    pub(super) body: Commander,
    pub(super) model: WorldModel,
    pub(super) mates: BTreeMap<u32, MateReport>,
    /// The team's ball booking (ThinkingCap/TeamChaos report §3.3, [`mrt_team::booking`]): fed by the
    /// behaviors' `bookBall`/`releaseBookedBall` and the teammates' reports.
    pub(super) booking: BallBooking,
    /// Teammates' booking reports received since the last frame.
    pub(super) booking_news: Vec<(u32, BookingReport)>,
    /// The behaviors' latest `bookBall` (true) or `releaseBookedBall` (false) not yet applied.
    pub(super) book: Option<bool>,
    /// The role the team agreed on at the last frame ([`mrt_team::roles`], `getRole`).
    pub(super) role: Role,
    /// SCARE (MRT manual ch. 11, [`mrt_team::scare`]): the activity the team gives this
    /// robot, its sub-task and goal, into the snapshot's `job` for Team Milan's parametric
    /// behaviors (Team Milan only).
    pub(super) scare: Option<Coordinator>,
    /// The latest frame to read this cycle: percepts, or a camera frame without an image.
    pub(super) frame: Option<MsgRef>,
    pub(super) inputs: Inputs<WorldState>,
}

impl WorldState {
    /// What the world state reads, and what it does with each.
    pub(super) fn inputs() -> Inputs<WorldState> {
        Inputs::<Self>::new()
            .on::<Odometry>(RequestType::Local, |s, o| s.model.odometry(o))
            .on_msg::<CameraFrame>(RequestType::Local, |s, m| {
                // A frame with an image is the vision µAgent's to read; its percepts follow.
                if m.get::<CameraFrame>().is_ok_and(|f| f.image.is_none()) {
                    s.frame = Some(m.clone());
                }
            })
            .on_msg::<Percepts>(RequestType::Local, |s, m| s.frame = Some(m.clone()))
            .on::<GameInfo>(RequestType::Local, |s, g| s.model.game(*g))
            // Read with the next frame (MAP's merger: echoes of robots out of view).
            .on::<SonarScan>(RequestType::Local, |s, scan| s.model.sonars(scan))
            .on::<RobotCommand>(RequestType::Local, |s, c| s.book = c.book_ball.or(s.book))
            .on::<MateReport>(RequestType::Remote, |s, r| {
                s.booking_news.push((r.id, r.booking.clone()));
                s.mates.insert(r.id, r.clone());
            })
    }
}

impl Member for WorldState {
    fn name(&self) -> String {
        format!("world-state-{}", self.robot)
    }

    fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        self.inputs.subscribe(ctx);
        Ok(())
    }

    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        self.inputs.clone().drain(self, ctx)?;
        let Some(frame) = self.frame.take() else { return Ok(()) };
        let mut w = match frame.get::<Percepts>() {
            Ok(p) => self.model.percepts(p),
            Err(_) => self.model.camera(frame.get::<CameraFrame>()?),
        };
        let id = u32::try_from(self.robot).unwrap_or(u32::MAX);
        // The ball's uncertainty (m), as the reports and the team ball count it.
        let ball_sigma = self.model.ball_sigma();
        let mut report =
            MateReport::of(id, self.keeper, &w).with_ball_sigma(ball_sigma.unwrap_or(0.0));
        // The ball booking on this frame's clock: the news, the behaviors' wish, the report.
        let now = w.time.as_secs_f64();
        for (from, b) in self.booking_news.drain(..) {
            self.booking.receive(now, from, &b);
        }
        if let Some(yes) = self.book.take() {
            self.booking.want(now, yes);
        }
        self.booking.update(now);
        report.booking = self.booking.report(now);
        w.ball_booked = self.booking.holds(now);
        // Teammates and their ball as the bus told them, not as the simulator knows them.
        merge_team(&mut w, ball_sigma, self.mates.values());
        // The roles, from the teammates heard lately (within the booking's `silent`: the
        // booking already keeps when each was last heard) and the team ball.
        let me = Player {
            id,
            at: (w.my_pos.pose.inner.x, w.my_pos.pose.inner.y),
            keeper: self.keeper,
            said: self.role,
        };
        let heard: Vec<&MateReport> =
            self.mates.values().filter(|r| self.booking.hears(r.id, now) && r.id != id).collect();
        let players: Vec<Player> = std::iter::once(me)
            .chain(heard.iter().map(|r| Player {
                id: r.id,
                at: (r.pose.pose.inner.x, r.pose.pose.inner.y),
                keeper: r.keeper,
                said: Role::from_name(&r.role).unwrap_or(Role::Defender),
            }))
            .collect();
        let ball = (w.global_ball.quality > BALL_KNOWN)
            .then_some((w.global_ball.pose.inner.x, w.global_ball.pose.inner.y));
        self.role = allocate(&players, ball).first().map_or(self.role, |r| r.1);
        report.role = self.role.name().to_string();
        w.role = self.role.name().to_string();
        // SCARE, on the same teammates and team ball.
        if let Some(scare) = &mut self.scare {
            let sit = situation(&w, self.keeper, ball, &heard);
            let shot = Geometry::of(&w.field).open_side(&w);
            let reports: Vec<_> = heard.iter().map(|r| (r.id, &r.scare)).collect();
            let cycle = scare.cycle(now, &sit, &reports, shot);
            report.scare = cycle.report;
            w.job = Some(cycle.job);
        }
        ctx.publish(report);
        ctx.publish(self.model.localization());
        self.body.perceive(&mut w);
        ctx.publish(w);
        Ok(())
    }
}

/// What SCARE's soccer activities read of a robot's beliefs: its pose, the team ball when
/// known, the teammates heard lately, the robots it anchored as opponents (or of unknown
/// team), the field.
pub(super) fn situation(
    w: &WorldSnapshot,
    keeper: bool,
    ball: Option<(f64, f64)>,
    heard: &[&MateReport],
) -> Situation {
    Situation {
        me: (w.my_pos.pose.inner.x, w.my_pos.pose.inner.y, w.my_pos.pose.inner.theta),
        keeper,
        ball,
        mates: heard
            .iter()
            .map(|r| (r.id, (r.pose.pose.inner.x, r.pose.pose.inner.y), r.keeper))
            .collect(),
        opponents: w
            .opponents(WorldSnapshot::ANCHORED)
            .map(|r| (r.at.inner.x, r.at.inner.y))
            .collect(),
        half_length: w.field.half_length,
        goal_half_width: w.field.goal_half_width,
    }
}
