//! SPIKE's map: the obstacles, the doors, the area, and the map file.

use crate::error::{positive, PlanError};
use mrt_core::Point2;

/// An obstacle of the map (MRT manual ch. 9: "a geometrical representation of fixed
/// objects"), or a moving object inserted for one plan.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// A round object: a pillar, a robot, a person.
    Disc {
        /// Its centre.
        centre: Point2,
        /// Its radius, m.
        radius: f64,
    },
    /// A thin wall from `a` to `b`.
    Wall {
        /// One end.
        a: Point2,
        /// The other end.
        b: Point2,
    },
    /// A filled polygon (furniture, a goal's box), its corners in order; concave allowed.
    Polygon(Vec<Point2>),
}

impl Shape {
    /// How far `p` lies from the shape, m; negative inside a disc or a polygon.
    pub fn distance(&self, p: Point2) -> f64 {
        match self {
            Shape::Disc { centre, radius } => (p - centre).norm() - radius,
            Shape::Wall { a, b } => segment_distance(p, *a, *b),
            Shape::Polygon(corners) => {
                let Some(&last) = corners.last() else {
                    return f64::INFINITY;
                };
                let mut d = f64::INFINITY;
                let mut inside = false;
                let mut prev = last;
                for &c in corners {
                    d = d.min(segment_distance(p, prev, c));
                    // Even-odd rule: count the edges a ray to +x crosses.
                    if (c.y > p.y) != (prev.y > p.y)
                        && p.x < prev.x + (p.y - prev.y) * (c.x - prev.x) / (c.y - prev.y)
                    {
                        inside = !inside;
                    }
                    prev = c;
                }
                if inside {
                    -d
                } else {
                    d
                }
            }
        }
    }

    /// How near the segment `a`–`b` comes to the shape, m (0 when it touches or crosses it).
    pub fn segment_distance(&self, a: Point2, b: Point2) -> f64 {
        match self {
            Shape::Disc { centre, radius } => (segment_distance(*centre, a, b) - radius).max(0.0),
            Shape::Wall { a: p, b: q } => segments_distance(a, b, *p, *q),
            Shape::Polygon(corners) => {
                if self.distance(a) <= 0.0 {
                    return 0.0;
                }
                let Some(&last) = corners.last() else {
                    return f64::INFINITY;
                };
                let mut prev = last;
                let mut d = f64::INFINITY;
                for &c in corners {
                    d = d.min(segments_distance(a, b, prev, c));
                    prev = c;
                }
                d
            }
        }
    }

    /// Whether every number is within [`MAX_COORD`] (so finite, and far from overflowing the
    /// geometry) and a disc's radius is not negative.
    pub(super) fn is_valid(&self) -> bool {
        let ok = |p: &Point2| p.x.abs() <= MAX_COORD && p.y.abs() <= MAX_COORD;
        match self {
            Shape::Disc { centre, radius } => ok(centre) && (0.0..=MAX_COORD).contains(radius),
            Shape::Wall { a, b } => ok(a) && ok(b),
            Shape::Polygon(corners) => corners.iter().all(ok),
        }
    }
}

impl Shape {
    /// A moving obstacle as the planner takes it: a disc larger than [`MAX_COORD`] (one that
    /// covers any map) at that radius, any other valid shape as it is, an invalid one
    /// (a number not finite or out of range, a negative radius) not at all.
    pub(super) fn bounded(&self) -> Option<Shape> {
        match *self {
            Shape::Disc { centre, radius } if radius > MAX_COORD => {
                Shape::Disc { centre, radius: MAX_COORD }.bounded()
            }
            _ => self.is_valid().then(|| self.clone()),
        }
    }
}

/// The largest coordinate or radius a map or a moving object may have, m: a thousand
/// kilometres, well inside what the geometry computes without overflow.
pub const MAX_COORD: f64 = 1e6;

/// The largest map file [`PlanMap::from_toml`] reads, bytes: some 20 000 obstacles, and a bound
/// on what parsing it allocates.
pub const MAX_MAP_BYTES: usize = 1 << 20;

/// The most doors a map file may have: the planner holds every cell against every door, so
/// that doors bound a plan's time as [`MAX_CELLS`](super::MAX_CELLS) bounds its cells.
pub const MAX_DOORS: usize = 256;

/// How far `p` lies from the segment `a`–`b`.
pub(super) fn segment_distance(p: Point2, a: Point2, b: Point2) -> f64 {
    let d = b - a;
    let t = ((p - a).dot(&d) / d.norm_squared().max(1e-18)).clamp(0.0, 1.0);
    (p - (a + d * t)).norm()
}

/// The side of `c` from the line `a`→`b`: positive on the left (counter-clockwise).
pub(super) fn cross(a: Point2, b: Point2, c: Point2) -> f64 {
    let (u, v) = (b - a, c - a);
    u.x * v.y - u.y * v.x
}

/// How near the segments `a`–`b` and `p`–`q` come, 0 when they cross.
fn segments_distance(a: Point2, b: Point2, p: Point2, q: Point2) -> f64 {
    let (d1, d2) = (cross(a, b, p), cross(a, b, q));
    let (d3, d4) = (cross(p, q, a), cross(p, q, b));
    if ((d1 > 0.0) != (d2 > 0.0)) && ((d3 > 0.0) != (d4 > 0.0)) {
        return 0.0;
    }
    segment_distance(a, p, q)
        .min(segment_distance(b, p, q))
        .min(segment_distance(p, a, b))
        .min(segment_distance(q, a, b))
}

/// A door (the manual: doors small with respect to the grid are handled; how is a design
/// choice): the gap between two jambs `a` and `b`. Within its region (closer to the gap than
/// the robot's radius plus the safety) the safety distance shrinks to what the door's width
/// leaves, so a door is passable when it is wider than the robot by a few times the
/// accuracy, and not when it is narrower.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Door {
    /// One jamb.
    pub a: Point2,
    /// The other jamb.
    pub b: Point2,
}

/// The environment SPIKE plans in: the area the robot may be in, the fixed obstacles, and the
/// doors.
#[derive(Clone, Debug, PartialEq)]
pub struct PlanMap {
    /// The area's lower-left corner.
    pub min: Point2,
    /// Its upper-right corner. The area's edge is a wall.
    pub max: Point2,
    /// The fixed obstacles.
    pub shapes: Vec<Shape>,
    /// The doors.
    pub doors: Vec<Door>,
}

impl PlanMap {
    /// An empty area from `min` to `max`.
    ///
    /// # Errors
    /// [`PlanError::InvalidParameter`] when a corner is not finite or `max` is not above and
    /// right of `min`.
    pub fn new(min: Point2, max: Point2) -> Result<PlanMap, PlanError> {
        for (name, v) in [("min.x", min.x), ("min.y", min.y), ("max.x", max.x), ("max.y", max.y)] {
            if !v.is_finite() || v.abs() > MAX_COORD {
                return Err(PlanError::InvalidParameter {
                    name,
                    value: v,
                    expected: "a finite value within ±1 000 000 m",
                });
            }
        }
        positive("max.x - min.x", max.x - min.x)?;
        positive("max.y - min.y", max.y - min.y)?;
        Ok(PlanMap { min, max, shapes: Vec::new(), doors: Vec::new() })
    }

    /// The map with one more obstacle.
    pub fn with(mut self, shape: Shape) -> PlanMap {
        self.shapes.push(shape);
        self
    }

    /// The map with one more door.
    pub fn with_door(mut self, door: Door) -> PlanMap {
        self.doors.push(door);
        self
    }

    /// A soccer field of `length` × `width` between its lines, origin at the centre spot, as
    /// MRT's simulator builds it: a 1 m border inside the walls, and each goal a box 2 m wide
    /// and 0.6 m deep behind its goal line (its back and sides are obstacles, its mouth is
    /// open).
    ///
    /// # Errors
    /// [`PlanError::InvalidParameter`] when a size is not finite and positive.
    pub fn soccer_field(length: f64, width: f64) -> Result<PlanMap, PlanError> {
        let (hl, hw) = (positive("length", length)? / 2.0, positive("width", width)? / 2.0);
        let border = 1.0;
        let (gw, gd) = (1.0, 0.6);
        let mut map = PlanMap::new(
            Point2::new(-hl - border, -hw - border),
            Point2::new(hl + border, hw + border),
        )?;
        for side in [-1.0, 1.0] {
            let (line, back) = (side * hl, side * (hl + gd));
            map = map
                .with(Shape::Wall { a: Point2::new(back, -gw), b: Point2::new(back, gw) })
                .with(Shape::Wall { a: Point2::new(line, gw), b: Point2::new(back, gw) })
                .with(Shape::Wall { a: Point2::new(line, -gw), b: Point2::new(back, -gw) });
        }
        Ok(map)
    }

    /// How far `p` lies from the nearest obstacle or the area's edge, m; negative inside an
    /// obstacle or outside the area.
    pub fn clearance(&self, p: Point2) -> f64 {
        let edge =
            (p.x - self.min.x).min(self.max.x - p.x).min(p.y - self.min.y).min(self.max.y - p.y);
        self.shapes.iter().fold(edge, |d, s| d.min(s.distance(p)))
    }
}

/// A map file (docs/planning.md): `[area]` or `[field]`, then any number of `[[disc]]`,
/// `[[wall]]`, `[[polygon]]` and `[[door]]` tables.
#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct MapFile {
    area: Option<AreaTable>,
    field: Option<FieldTable>,
    #[serde(default)]
    disc: Vec<DiscTable>,
    #[serde(default)]
    wall: Vec<SegmentTable>,
    #[serde(default)]
    polygon: Vec<PolygonTable>,
    #[serde(default)]
    door: Vec<SegmentTable>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct AreaTable {
    min: [f64; 2],
    max: [f64; 2],
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct FieldTable {
    length: f64,
    width: f64,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct DiscTable {
    centre: [f64; 2],
    radius: f64,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct SegmentTable {
    from: [f64; 2],
    to: [f64; 2],
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct PolygonTable {
    corners: Vec<[f64; 2]>,
}

impl PlanMap {
    /// Parses a map file (TOML, docs/planning.md); `file` names it in errors, with the line
    /// and column of a syntax error.
    ///
    /// ```
    /// let text = "[area]\nmin = [0, 0]\nmax = [6, 4]\n\n[[disc]]\ncentre = [3, 2]\nradius = 0.5\n";
    /// let map = mrt_plan::spike::PlanMap::from_toml(text, "room.toml")?;
    /// assert_eq!(map.shapes.len(), 1);
    /// let bad = mrt_plan::spike::PlanMap::from_toml("[area]\nmin = [0, 0]\nmax = 4\n", "bad.toml");
    /// assert!(bad.unwrap_err().to_string().starts_with("bad.toml:3:7: "));
    /// # Ok::<(), mrt_core::FileError>(())
    /// ```
    ///
    /// # Errors
    /// [`mrt_core::FileError::Parse`] for malformed TOML or an unknown key,
    /// [`mrt_core::FileError::Invalid`] for an area and a field both or neither, a size that
    /// is not positive, a number that is not finite or beyond [`MAX_COORD`], a polygon of
    /// fewer than 3 corners, more than [`MAX_DOORS`] doors, or a file longer than
    /// [`MAX_MAP_BYTES`].
    pub fn from_toml(text: &str, file: &str) -> Result<PlanMap, mrt_core::FileError> {
        if text.len() > MAX_MAP_BYTES {
            return Err(mrt_core::FileError::Invalid {
                file: file.to_string(),
                message: format!(
                    "{} bytes: a map file may have at most {MAX_MAP_BYTES}",
                    text.len()
                ),
            });
        }
        let parsed: MapFile = toml::from_str(text).map_err(|e| {
            mrt_core::FileError::parse(file, text, e.span().map(|s| s.start), e.message())
        })?;
        let invalid =
            |message: String| mrt_core::FileError::Invalid { file: file.to_string(), message };
        let point = |[x, y]: [f64; 2]| Point2::new(x, y);
        let mut map = match (parsed.area, parsed.field) {
            (Some(a), None) => PlanMap::new(point(a.min), point(a.max)),
            (None, Some(f)) => PlanMap::soccer_field(f.length, f.width),
            _ => return Err(invalid("give either [area] or [field], not both or neither".into())),
        }
        .map_err(|e| invalid(e.to_string()))?;
        for d in parsed.disc {
            map = map.with(Shape::Disc { centre: point(d.centre), radius: d.radius });
        }
        for w in parsed.wall {
            map = map.with(Shape::Wall { a: point(w.from), b: point(w.to) });
        }
        for (k, p) in parsed.polygon.into_iter().enumerate() {
            if p.corners.len() < 3 {
                return Err(invalid(format!(
                    "polygon {}: {} corners, at least 3 needed",
                    k + 1,
                    p.corners.len()
                )));
            }
            map = map.with(Shape::Polygon(p.corners.into_iter().map(point).collect()));
        }
        if parsed.door.len() > MAX_DOORS {
            return Err(invalid(format!(
                "{} doors: a map may have at most {MAX_DOORS}",
                parsed.door.len()
            )));
        }
        for d in parsed.door {
            map = map.with_door(Door { a: point(d.from), b: point(d.to) });
        }
        if let Some(k) = map.shapes.iter().position(|s| !s.is_valid()) {
            return Err(invalid(format!(
                "obstacle {}: a number is not finite or beyond ±{MAX_COORD} m, or a radius is negative",
                k + 1
            )));
        }
        let near = |p: &Point2| p.x.abs() <= MAX_COORD && p.y.abs() <= MAX_COORD;
        if map.doors.iter().any(|d| !near(&d.a) || !near(&d.b)) {
            return Err(invalid(format!("a door's jamb is not finite or beyond ±{MAX_COORD} m")));
        }
        Ok(map)
    }

    /// Reads a map file ([`PlanMap::from_toml`]).
    ///
    /// # Errors
    /// [`mrt_core::FileError::Io`] when the file cannot be read, else as
    /// [`PlanMap::from_toml`].
    pub fn from_file(path: impl AsRef<std::path::Path>) -> Result<PlanMap, mrt_core::FileError> {
        let (text, file) = mrt_core::FileError::read(path.as_ref())?;
        PlanMap::from_toml(&text, &file)
    }
}
