//! The pose filter's steps: prediction by odometry, correction by nets, landmarks and field
//! lines (gated innovations), and relocation by the global localizers.

use super::*;

impl WorldModel {
    /// Puts the filter where the relocalizer's `fix` says, as sure as MUREA's accuracy and
    /// the perceptions' tolerances allow.
    pub(super) fn relocate(&mut self, fix: &Fix) {
        self.relocate_to(fix.pose, fix.cell.0, fix.cell.2);
    }

    /// Puts the filter at `pose`, at least `xy` (m) and `theta` (rad) unsure.
    pub(super) fn relocate_to(&mut self, pose: Pose2, xy: f64, theta: f64) {
        self.pose = pose;
        let (xy, theta) = (RELOCATED_SIGMA.0.max(xy), RELOCATED_SIGMA.1.max(theta));
        self.cov = Matrix3::from_diagonal(&Vector3::new(xy * xy, xy * xy, theta * theta));
        self.counts.relocalized += 1;
        self.lines_trusted = false;
        self.robots.reset();
    }

    /// The EKF prediction: the pose moves by `d` (robot frame); the uncertainty grows with
    /// `sigma` = (fraction of the motion, turn error per metre).
    pub(super) fn predict(&mut self, d: &Displacement, sigma: (f64, f64)) {
        if !(d.dx.is_finite() && d.dy.is_finite() && d.dtheta.is_finite()) {
            return;
        }
        let (s, c) = self.pose.theta.sin_cos();
        let f = Matrix3::new(
            1.0,
            0.0,
            -s * d.dx - c * d.dy,
            0.0,
            1.0,
            c * d.dx - s * d.dy,
            0.0,
            0.0,
            1.0,
        );
        let dist = d.dx.hypot(d.dy);
        let fwd = sigma.0 * d.dx.abs() + FLOOR.0;
        let side = sigma.0 * d.dy.abs() + FLOOR.0;
        let turn = sigma.0 * d.dtheta.abs() + sigma.1 * dist + FLOOR.1;
        let q = Matrix3::from_diagonal(&Vector3::new(fwd * fwd, side * side, turn * turn));
        let rot = Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0);
        self.cov = f * self.cov * f.transpose() + rot * q * rot.transpose();
        let p = self.pose.compose(&d.as_pose());
        self.pose = Pose2::new(p.x, p.y, normalize_angle(p.theta));
        let o = self.odom.compose(&d.as_pose());
        self.odom = Pose2::new(o.x, o.y, normalize_angle(o.theta));
        if let Some(r) = &mut self.relocalizer {
            r.moved(d.as_pose());
        }
        if let Some(g) = &mut self.grid {
            g.predict(d.as_pose());
        }
    }

    /// Field position (m) of field object `k` (1..: nets and landmarks, sensor order).
    /// Where camera object `k` stands on the map (`None` for the ball).
    pub(super) fn landmark(&self, k: usize) -> Option<(f64, f64)> {
        self.map.object(k).map(|p| (p.x, p.y))
    }

    /// The EKF's view of one sighting `z` of a landmark at `at` with the sensor's own
    /// standard deviations `sigma` (where known): the measurement Jacobian, the innovation, its
    /// covariance's inverse, the measurement noise and the squared Mahalanobis distance.
    /// `None` when the landmark is too close to linearise or the numbers are not finite.
    pub(super) fn innovation(
        &self,
        at: (f64, f64),
        z: &Sighting,
        sigma: Option<(f64, f64)>,
    ) -> Option<Innovation> {
        let (dx, dy) = (at.0 - self.pose.x, at.1 - self.pose.y);
        let q = dx * dx + dy * dy;
        let rho = q.sqrt();
        if rho < 0.3 || !(z.distance.is_finite() && z.bearing.is_finite()) {
            return None;
        }
        let h = Matrix2x3::new(-dx / rho, -dy / rho, 0.0, dy / q, -dx / q, -1.0);
        let nu = Vector2::new(
            z.distance - rho,
            normalize_angle(z.bearing - (dy.atan2(dx) - self.pose.theta)),
        );
        // The vision µAgent's own estimate, where larger: a far net's distance rests on a
        // pixel row that spans half a metre of floor.
        let (sd, sb) = self.noise.sigma(z.distance, sigma);
        let r = Matrix2::new(sd * sd, 0.0, 0.0, sb * sb);
        let s_inv = (h * self.cov * h.transpose() + r).try_inverse()?;
        let d2 = (nu.transpose() * s_inv * nu)[(0, 0)];
        d2.is_finite().then_some(Innovation { h, nu, s_inv, r, d2 })
    }

    /// The EKF correction by one sighting of a landmark at `at`. Returns whether it was
    /// accepted (not gated out).
    pub(super) fn correct(
        &mut self,
        at: (f64, f64),
        z: &Sighting,
        sigma: Option<(f64, f64)>,
    ) -> bool {
        let Some(Innovation { h, nu, s_inv, r, d2 }) = self.innovation(at, z, sigma) else {
            return true; // too close to linearise; nothing learnt, nothing wrong
        };
        if d2 > GATE {
            return false;
        }
        let k = self.cov * h.transpose() * s_inv;
        // Joseph form: stays symmetric and positive.
        let i_kh = Matrix3::identity() - k * h;
        self.commit(k * nu, i_kh * self.cov * i_kh.transpose() + k * r * k.transpose());
        true
    }

    /// Moves the pose by an EKF correction's `step` and sets its covariance to `cov`, unless
    /// either is not finite: then both stay as they were and the refusal is counted.
    /// Returns whether it was applied.
    pub(super) fn commit(&mut self, step: Vector3<f64>, cov: Matrix3<f64>) -> bool {
        if !(step.iter().chain(cov.iter()).all(|v| v.is_finite())) {
            self.counts.refused += 1;
            return false;
        }
        self.pose = Pose2::new(
            self.pose.x + step[0],
            self.pose.y + step[1],
            normalize_angle(self.pose.theta + step[2]),
        );
        self.cov = cov;
        true
    }

    /// Which landmark a post of the vision is (data association): of the posts wearing its
    /// pattern ([`FieldMap::east_pattern`]), the one its sighting fits best by the squared
    /// Mahalanobis distance, when that fit passes the [`GATE`] and the second best fits
    /// [`AMBIGUITY`] times worse or fails the gate. A robot unsure where it is leaves its
    /// posts unnamed (the nets, unique, put it right first).
    pub(super) fn associate(&self, post: &PostSighting) -> Option<usize> {
        let mut fits: Vec<(usize, f64)> = (lps::LANDMARK0..FIELD_OBJECTS)
            .filter(|&k| self.map.east_pattern(k) == Some(post.east))
            .filter_map(|k| {
                let at = self.landmark(k)?;
                Some((k, self.innovation(at, &post.sighting, Some(post.sigma))?.d2))
            })
            .collect();
        fits.sort_by(|a, b| a.1.total_cmp(&b.1));
        let (best, d2) = *fits.first()?;
        let clear = fits.get(1).is_none_or(|&(_, next)| next > GATE || next > AMBIGUITY * d2);
        (d2 <= GATE && clear).then_some(best)
    }

    /// Corrects the pose with every net and landmark of `frame`. Returns how many were seen
    /// and how many of them were rejected.
    pub(super) fn correct_all(
        &mut self,
        frame: &CameraFrame,
        sigmas: &[Option<(f64, f64)>; FIELD_OBJECTS],
    ) -> (u64, u64) {
        let (mut seen, mut rejected) = (0, 0);
        for (k, z) in frame.sightings.iter().enumerate() {
            let (Some(z), Some(at)) = (z, self.landmark(k)) else { continue };
            seen += 1;
            if self.correct(at, z, sigmas[k]) {
                self.counts.corrections += 1;
            } else {
                rejected += 1;
            }
        }
        self.counts.rejected += rejected;
        (seen, rejected)
    }

    /// Corrects the pose with the field-line points of a frame (robot frame, m): up to
    /// [`LINE_CORRECTIONS`] of them within [`LINE_RANGE`], the nearest first, each that lies
    /// beside one line of the map by the current estimate ([`FieldMap::line_fit`]). A point
    /// measures its signed distance from that line, which is 0 when the pose is right: a
    /// scalar EKF update whose Jacobian is the line's normal `n` for the position and
    /// `n · ∂p/∂θ` for the heading. A point tells nothing along its line, so a frame of one
    /// line corrects the pose across it only, and the corner of two lines fixes the position.
    /// This is how ISocRob's "self" localization used the lines (ISocRob-2000 report §3.2.1), as an
    /// EKF update instead of a Hough match: the lines are in nearly every frame, the goals and
    /// posts far and few.
    pub(super) fn correct_lines(&mut self, line_points: &[Framed<Robot, Point2>]) {
        let mut near: Vec<(f64, f64, f64)> = line_points
            .iter()
            .map(|p| (p.inner.coords.norm(), p.inner.x, p.inner.y))
            .filter(|&(d, _, _)| d.is_finite() && (LINE_MIN_RANGE..=LINE_RANGE).contains(&d))
            .collect();
        near.sort_by(|a, b| a.0.total_cmp(&b.0));
        for &(d, x, y) in near.iter().take(LINE_CORRECTIONS) {
            let at = self.pose.transform_point(Point2::new(x, y));
            let Some(fit) = self.map.line_fit(at, LINE_CLEARANCE) else { continue };
            let n = fit.normal;
            // The point seen from the robot in the field frame; turned a quarter, its
            // derivative by the heading.
            let seen = at - self.pose.position();
            let turn = Vector2::new(-seen.y, seen.x);
            let h = nalgebra::RowVector3::new(n.x, n.y, n.dot(&turn));
            // The point's error along the normal: the range's along the line of sight, the
            // bearing's across it.
            let (sd, sb) = self.noise.sigma(d, None);
            let sight = seen / d.max(1e-6);
            let along = n.dot(&sight).powi(2);
            let r = LINE_INFLATION * (sd * sd * along + (d * sb).powi(2) * (1.0 - along));
            let s_var = (h * self.cov * h.transpose())[(0, 0)] + r;
            let nu = -fit.residual;
            let d2 = nu * nu / s_var;
            if !d2.is_finite() || s_var <= 0.0 || d2 > LINE_GATE {
                continue;
            }
            let k = self.cov * h.transpose() / s_var;
            let i_kh = Matrix3::identity() - k * h;
            if self.commit(k * nu, i_kh * self.cov * i_kh.transpose() + k * r * k.transpose()) {
                self.counts.line_corrections += 1;
            }
        }
    }
}
