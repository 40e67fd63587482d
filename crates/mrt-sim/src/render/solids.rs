//! The solids a camera sees besides the floor (goals, posts, the ball, robots) and how a
//! row of rays meets them: [`Shape::trace_row`] traces a row in `f32` in loops the compiler
//! vectorizes, [`Shape::hit`] one ray in `f64` (a distorting lens's pixels).

/// One object's hits on a run of pixels of a row, one element a pixel: the distance along
/// the ray (infinite: a miss), the height hit and the shading factor.
pub(super) struct Hits<'a> {
    pub(super) ts: &'a mut [f32],
    pub(super) zs: &'a mut [f32],
    pub(super) shades: &'a mut [f32],
}

impl Hits<'_> {
    pub(super) fn of(hit: Option<Hit>) -> (f32, f32, f32) {
        hit.map_or((f32::INFINITY, 0.0, 1.0), |(t, z, shade)| (t as f32, z as f32, shade as f32))
    }
}

/// How a thing is painted: bands from the floor up, each to its top height (m).
#[derive(Clone, Copy, Debug)]
pub(super) struct Bands {
    pub(super) tops: [f64; 3],
    pub(super) colours: [[u8; 3]; 3],
}

impl Bands {
    pub(super) fn flat(colour: [u8; 3]) -> Bands {
        Bands { tops: [f64::INFINITY; 3], colours: [colour; 3] }
    }
}

/// A thing's bands under one frame's lighting, ready for its pixels.
pub(super) struct Lit {
    /// The tops of the lower two bands.
    pub(super) tops: [f32; 2],
    /// Each band's colour under the frame's brightness.
    pub(super) rgb: [[u32; 3]; 3],
}

impl Lit {
    pub(super) fn new(bands: &Bands, brightness: f64) -> Lit {
        let lit = |v: u8| (f64::from(v) * brightness).clamp(0.0, 255.0) as u32;
        Lit {
            tops: [bands.tops[0] as f32, bands.tops[1] as f32],
            rgb: bands.colours.map(|c| c.map(lit)),
        }
    }

    /// The colour at height `z` with the shading factor `shade`.
    #[inline(always)]
    pub(super) fn colour(&self, z: f32, shade: f32) -> [u8; 3] {
        let band = if z <= self.tops[0] {
            &self.rgb[0]
        } else if z <= self.tops[1] {
            &self.rgb[1]
        } else {
            &self.rgb[2]
        };
        // In 1/256ths: integer arithmetic a channel.
        let k = (shade * 256.0) as u32;
        band.map(|v| ((v * k) >> 8).min(255) as u8)
    }
}

/// A solid the camera may see, field frame.
#[derive(Clone, Copy, Debug)]
pub(super) enum Shape {
    Sphere {
        c: [f64; 3],
        r: f64,
    },
    /// Vertical, standing on the floor.
    Cylinder {
        x: f64,
        y: f64,
        r: f64,
        top: f64,
    },
    /// Axis-aligned.
    Cuboid {
        min: [f64; 3],
        max: [f64; 3],
    },
}

/// A hit: the distance along the ray (in units of the ray's length), the height hit and the
/// shading factor.
pub(super) type Hit = (f64, f64, f64);

impl Shape {
    pub(super) fn bounds(&self) -> ([f64; 3], [f64; 3]) {
        match *self {
            Shape::Sphere { c, r } => {
                ([c[0] - r, c[1] - r, c[2] - r], [c[0] + r, c[1] + r, c[2] + r])
            }
            Shape::Cylinder { x, y, r, top } => ([x - r, y - r, 0.0], [x + r, y + r, top]),
            Shape::Cuboid { min, max } => (min, max),
        }
    }

    /// The solid seen from the optical centre `eye` (field frame) with the camera's axes,
    /// turned by `(sin, cos)` of its heading from the field's: spheres and cylinders are moved
    /// and turned; a cuboid keeps the field's axes, moved only ([`Shape::hit`] turns the ray).
    pub(super) fn relative(&self, eye: [f64; 3], (s, c): (f64, f64)) -> Shape {
        let turn = |x: f64, y: f64| {
            let (dx, dy) = (x - eye[0], y - eye[1]);
            (c * dx + s * dy, -s * dx + c * dy)
        };
        match *self {
            Shape::Sphere { c: centre, r } => {
                let (x, y) = turn(centre[0], centre[1]);
                Shape::Sphere { c: [x, y, centre[2]], r }
            }
            Shape::Cylinder { x, y, r, top } => {
                let (x, y) = turn(x, y);
                Shape::Cylinder { x, y, r, top }
            }
            Shape::Cuboid { min, max } => Shape::Cuboid {
                min: [min[0] - eye[0], min[1] - eye[1], min[2]],
                max: [max[0] - eye[0], max[1] - eye[1], max[2]],
            },
        }
    }

    /// The directions (camera axes, seen from above) of the right and left edges of the
    /// wedge of rays from the eye that may meet the solid (placed by [`Shape::relative`]):
    /// the tangents to a disc, or the outermost corners of a rectangle; `None` when the eye
    /// stands over its footprint. `(sin, cos)` turns the camera's axes into the field's (a
    /// cuboid's).
    pub(super) fn wedge(&self, (s, c): (f64, f64)) -> Option<([f64; 2], [f64; 2])> {
        Some(match *self {
            Shape::Sphere { c: [x, y, _], r } | Shape::Cylinder { x, y, r, .. } => {
                let l2 = x * x + y * y;
                if l2 <= r * r {
                    return None;
                }
                let l = l2.sqrt();
                let (sb, cb) = (r / l, (1.0 - r * r / l2).sqrt());
                let (ux, uy) = (x / l, y / l);
                // The tangents: the direction to the axis turned by ∓asin(r / l).
                ([cb * ux + sb * uy, -sb * ux + cb * uy], [cb * ux - sb * uy, sb * ux + cb * uy])
            }
            Shape::Cuboid { min, max } => {
                if min[0] <= 0.0 && max[0] >= 0.0 && min[1] <= 0.0 && max[1] >= 0.0 {
                    return None;
                }
                // The footprint's corners in the camera's axes, and their angles from the
                // direction to its centre (the eye is outside it: they span less than π).
                let turn = |x: f64, y: f64| [c * x + s * y, -s * x + c * y];
                let u = turn((min[0] + max[0]) / 2.0, (min[1] + max[1]) / 2.0);
                let corners = [
                    turn(min[0], min[1]),
                    turn(max[0], min[1]),
                    turn(min[0], max[1]),
                    turn(max[0], max[1]),
                ];
                let angle =
                    corners.map(|p| (u[0] * p[1] - u[1] * p[0]).atan2(u[0] * p[0] + u[1] * p[1]));
                let by_angle = |a: &usize, b: &usize| angle[*a].total_cmp(&angle[*b]);
                (corners[(0..4).min_by(by_angle)?], corners[(0..4).max_by(by_angle)?])
            }
        })
    }

    /// The hits of the rays `start + k·step` of the columns `k0, k0 + 1, ...` of a row, one a
    /// pixel (see [`Hits`]). Cylinders, most of what a camera sees of other robots, are traced
    /// in a loop without branches that the compiler vectorizes; the other solids go through
    /// [`Shape::hit`].
    pub(super) fn trace_row(
        &self,
        o: [f64; 3],
        (start, step): ([f64; 3], [f64; 3]),
        k0: usize,
        (s, c): (f64, f64),
        hits: Hits,
    ) {
        let k0 = k0 as f64;
        let Hits { ts, zs, shades } = hits;
        // Relative to the column k0, in f32 (image-level accuracy): the ray of the j-th pixel
        // is (sx + j·tx, sy + j·ty, dz) from (0, 0, ez).
        let (sx, sy) = ((start[0] + k0 * step[0]) as f32, (start[1] + k0 * step[1]) as f32);
        let (tx, ty, dz) = (step[0] as f32, step[1] as f32, start[2] as f32);
        let ez = o[2] as f32;
        let pixels = ts.iter_mut().zip(zs).zip(shades).enumerate();
        match *self {
            Shape::Cylinder { x, y, r, top } => {
                let (ox, oy) = ((o[0] - x) as f32, (o[1] - y) as f32);
                let (r, top) = (r as f32, top as f32);
                let cc = ox * ox + oy * oy - r * r;
                // The top is met, if at all, at one distance along every ray of the row.
                let t_top = (top - ez) / dz;
                let top_seen = dz < 0.0 && t_top > 0.0;
                // The light from the field's north-east, in the camera's axes.
                let light = std::f32::consts::FRAC_1_SQRT_2 / r;
                let (lx, ly) = (((c + s) as f32) * light, ((c - s) as f32) * light);
                for (j, ((t_out, z_out), shade_out)) in pixels {
                    let k = j as f32;
                    let (dx, dy) = (sx + k * tx, sy + k * ty);
                    let a = dx * dx + dy * dy;
                    let b = ox * dx + oy * dy;
                    let disc = b * b - a * cc;
                    let t = (-b - disc.max(0.0).sqrt()) / a;
                    let z = ez + t * dz;
                    let side = disc >= 0.0 && t > 0.0 && z >= 0.0 && z <= top;
                    let (px, py) = (ox + t_top * dx, oy + t_top * dy);
                    let cap = top_seen && px * px + py * py <= r * r;
                    let shade = 0.9 + 0.1 * ((ox + t * dx) * lx + (oy + t * dy) * ly);
                    *t_out = if side {
                        t
                    } else if cap {
                        t_top
                    } else {
                        f32::INFINITY
                    };
                    *z_out = if side { z } else { top };
                    *shade_out = if side { shade } else { 1.0 };
                }
            }
            Shape::Sphere { c: centre, r } => {
                let oc =
                    [(o[0] - centre[0]) as f32, (o[1] - centre[1]) as f32, ez - centre[2] as f32];
                let r = r as f32;
                let cc = oc[0] * oc[0] + oc[1] * oc[1] + oc[2] * oc[2] - r * r;
                let (bz, cz) = (oc[2] * dz, centre[2] as f32);
                for (j, ((t_out, z_out), shade_out)) in pixels {
                    let k = j as f32;
                    let (dx, dy) = (sx + k * tx, sy + k * ty);
                    let a = dx * dx + dy * dy + dz * dz;
                    let b = oc[0] * dx + oc[1] * dy + bz;
                    let disc = b * b - a * cc;
                    let t = (-b - disc.max(0.0).sqrt()) / a;
                    let z = ez + t * dz;
                    *t_out = if disc >= 0.0 && t > 0.0 { t } else { f32::INFINITY };
                    *z_out = z;
                    // Lit from above: the top bright, the underside darker.
                    *shade_out = 0.8 + 0.2 * (z - cz) / r;
                }
            }
            Shape::Cuboid { min, max } => {
                // The slabs in the field's axes: the ray turned, and its inverse per axis (an
                // axis the ray runs along gives ±∞, or NaN on a face, which `min`/`max` skip).
                let (sc, ss) = (c as f32, s as f32);
                let (min, max) = (min.map(|v| v as f32), max.map(|v| v as f32));
                let (lo_z, hi_z) = ((min[2] - ez) / dz, (max[2] - ez) / dz);
                let (tz0, tz1) = (lo_z.min(hi_z), lo_z.max(hi_z));
                for (j, ((t_out, z_out), shade_out)) in pixels {
                    let k = j as f32;
                    let (dx, dy) = (sx + k * tx, sy + k * ty);
                    let (fx, fy) = (sc * dx - ss * dy, ss * dx + sc * dy);
                    let (ax, bx) = (min[0] / fx, max[0] / fx);
                    let (ay, by) = (min[1] / fy, max[1] / fy);
                    let t0 = ax.min(bx).max(ay.min(by)).max(tz0).max(0.0);
                    let t1 = ax.max(bx).min(ay.max(by)).min(tz1);
                    let hit = t0 <= t1 && t0 > 0.0;
                    *t_out = if hit { t0 } else { f32::INFINITY };
                    *z_out = ez + t0 * dz;
                    *shade_out = 1.0;
                }
            }
        }
    }

    /// Where the ray `o + t·d` (t > 0) first meets the solid; `(sin, cos)` turns the camera's
    /// axes into the field's (a cuboid's, and the light's).
    pub(super) fn hit(&self, o: [f64; 3], d: [f64; 3], (s, c): (f64, f64)) -> Option<Hit> {
        match *self {
            Shape::Sphere { c, r } => {
                let oc = [o[0] - c[0], o[1] - c[1], o[2] - c[2]];
                let a = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                let b = oc[0] * d[0] + oc[1] * d[1] + oc[2] * d[2];
                let cc = oc[0] * oc[0] + oc[1] * oc[1] + oc[2] * oc[2] - r * r;
                let disc = b * b - a * cc;
                if disc < 0.0 {
                    return None;
                }
                let t = (-b - disc.sqrt()) / a;
                let z = o[2] + t * d[2];
                // Lit from above: the top bright, the underside darker.
                (t > 0.0).then(|| (t, z, 0.8 + 0.2 * (z - c[2]) / r))
            }
            Shape::Cylinder { x, y, r, top } => {
                let (ox, oy) = (o[0] - x, o[1] - y);
                let a = d[0] * d[0] + d[1] * d[1];
                let b = ox * d[0] + oy * d[1];
                let cc = ox * ox + oy * oy - r * r;
                let disc = b * b - a * cc;
                if a > 0.0 && disc >= 0.0 {
                    let t = (-b - disc.sqrt()) / a;
                    let z = o[2] + t * d[2];
                    if t > 0.0 && (0.0..=top).contains(&z) {
                        // Lit from the north-east of the field, a little.
                        let (nx, ny) = ((ox + t * d[0]) / r, (oy + t * d[1]) / r);
                        let (nx, ny) = (c * nx - s * ny, s * nx + c * ny);
                        return Some((
                            t,
                            z,
                            0.9 + 0.1 * (nx + ny) * std::f64::consts::FRAC_1_SQRT_2,
                        ));
                    }
                }
                // The top, seen from above.
                if d[2] < 0.0 {
                    let t = (top - o[2]) / d[2];
                    let (px, py) = (ox + t * d[0], oy + t * d[1]);
                    if t > 0.0 && px * px + py * py <= r * r {
                        return Some((t, top, 1.0));
                    }
                }
                None
            }
            Shape::Cuboid { min, max } => {
                let d = [c * d[0] - s * d[1], s * d[0] + c * d[1], d[2]];
                let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
                for k in 0..3 {
                    if d[k] == 0.0 {
                        if o[k] < min[k] || o[k] > max[k] {
                            return None;
                        }
                        continue;
                    }
                    let (a, b) = ((min[k] - o[k]) / d[k], (max[k] - o[k]) / d[k]);
                    t0 = t0.max(a.min(b));
                    t1 = t1.min(a.max(b));
                }
                (t0 <= t1 && t0 > 0.0).then(|| (t0, o[2] + t0 * d[2], 1.0))
            }
        }
    }
}

#[derive(Clone, Copy, Debug)]
pub(super) struct Thing {
    pub(super) shape: Shape,
    pub(super) paint: Bands,
}
