//! The route the ego vehicle drives along a map's lane graph in a `sequence`: the centre
//! line of its lane from where `[road]` places it, through the lanes after it, as a
//! polyline in the world frame.

use glam::DVec3;

/// A lane centre line to drive along, world frame (metres), in the direction of travel.
#[derive(Clone, Debug, PartialEq)]
pub struct LaneRoute {
    /// At least two points, each a different place; the first is the ego lane's centre at
    /// t = 0.
    points: Vec<DVec3>,
    /// Arc length at each point, metres, from 0.
    along: Vec<f64>,
    /// The unit horizontal travel direction at each point: the mean of the two segments
    /// beside it (a circle's tangent, where they are alike), so that the heading turns
    /// smoothly from one segment to the next.
    headings: Vec<DVec3>,
}

/// Where a route puts the vehicle: its lane centre and horizontal heading.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoutePose {
    pub position: DVec3,
    /// Unit, horizontal (y = 0).
    pub heading: DVec3,
}

impl LaneRoute {
    /// The route through `points` (world frame, in travel order): points within a millimetre
    /// of the one before are dropped. `None` if fewer than two remain.
    pub fn new(points: impl IntoIterator<Item = DVec3>) -> Option<LaneRoute> {
        let mut kept: Vec<DVec3> = Vec::new();
        for p in points {
            if kept.last().is_none_or(|q| q.distance(p) > 1e-3) {
                kept.push(p);
            }
        }
        if kept.len() < 2 {
            return None;
        }
        let flat = |v: DVec3| DVec3::new(v.x, 0.0, v.z).normalize_or_zero();
        let segment = |i: usize| flat(kept[i + 1] - kept[i]);
        let last = kept.len() - 1;
        let mut headings: Vec<DVec3> = (0..=last)
            .map(|i| match i {
                0 => segment(0),
                i if i == last => segment(last - 1),
                i => (segment(i - 1) + segment(i)).normalize_or(segment(i)),
            })
            .collect();
        // A chord's direction lies halfway between the tangents at its ends: the tangent at
        // an end is the chord's direction turned as far again past its inner neighbour's.
        if last >= 2 {
            headings[0] = (2.0 * segment(0) - headings[1]).normalize_or(segment(0));
            headings[last] =
                (2.0 * segment(last - 1) - headings[last - 1]).normalize_or(segment(last - 1));
        }
        let mut along = vec![0.0];
        for w in kept.windows(2) {
            along.push(along.last().expect("one") + w[0].distance(w[1]));
        }
        Some(LaneRoute {
            points: kept,
            along,
            headings,
        })
    }

    /// Its length, metres.
    pub fn length(&self) -> f64 {
        *self.along.last().expect("two points")
    }

    /// The pose `s` metres along; before the start and past the end, straight on along the
    /// heading there.
    pub fn pose_at(&self, s: f64) -> RoutePose {
        let last = self.points.len() - 1;
        if s >= self.length() {
            let heading = self.headings[last];
            return RoutePose {
                position: self.points[last] + (s - self.length()) * heading,
                heading,
            };
        }
        if s < 0.0 {
            // Before t = 0 (a scanout's refresh before the first frame): straight, backwards.
            let heading = self.headings[0];
            return RoutePose {
                position: self.points[0] + s * heading,
                heading,
            };
        }
        let i = self.along.partition_point(|&a| a <= s).clamp(1, last) - 1;
        let f = (s - self.along[i]) / (self.along[i + 1] - self.along[i]);
        RoutePose {
            position: self.points[i].lerp(self.points[i + 1], f),
            heading: self.headings[i]
                .lerp(self.headings[i + 1], f)
                .normalize_or(self.headings[i]),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_quarter_circle_route_keeps_its_radius_and_turns_its_heading() {
        let r = 11.75;
        let points = (0..=200).map(|k| {
            let a = std::f64::consts::FRAC_PI_2 * f64::from(k) / 200.0;
            // Centre (−r, 0, 0); starts at the origin heading −z, turns left towards −x.
            DVec3::new(-r + r * a.cos(), 0.0, -r * a.sin())
        });
        let route = LaneRoute::new(points).unwrap();
        let quarter = std::f64::consts::FRAC_PI_2 * r;
        // The chords' length is the arc's less its sagitta loss: (1 − sinc) ≈ δ²/24.
        assert!((route.length() - quarter).abs() / quarter < 1e-4);
        for k in 0..=10 {
            let pose = route.pose_at(quarter * f64::from(k) / 10.0);
            let radius = pose.position.distance(DVec3::new(-r, 0.0, 0.0));
            assert!((radius - r).abs() < 2e-3, "radius {radius}");
            let a = std::f64::consts::FRAC_PI_2 * f64::from(k) / 10.0;
            let tangent = DVec3::new(-a.sin(), 0.0, -a.cos());
            // Within a tenth of the chords' 0.45° turn, the ends included.
            let off = pose.heading.dot(tangent).clamp(-1.0, 1.0).acos();
            assert!(
                off < 0.1 * std::f64::consts::FRAC_PI_2 / 200.0,
                "k {k}: {off} rad"
            );
        }
        // Past the end: straight on, west.
        let beyond = route.pose_at(route.length() + 5.0);
        assert!(beyond.position.distance(DVec3::new(-r - 5.0, 0.0, -r)) < 1e-3);
        // Before the start: straight back, along +z.
        let before = route.pose_at(-2.0);
        assert!(before.position.distance(DVec3::new(0.0, 0.0, 2.0)) < 1e-3);
    }

    #[test]
    fn repeated_points_are_dropped_and_one_point_is_no_route() {
        let p = DVec3::new(1.0, 0.0, 2.0);
        assert!(LaneRoute::new([p, p]).is_none());
        let route = LaneRoute::new([p, p, p + DVec3::NEG_Z]).unwrap();
        assert_eq!(route.length(), 1.0);
        assert_eq!(route.pose_at(0.5).position, p + 0.5 * DVec3::NEG_Z);
    }
}
