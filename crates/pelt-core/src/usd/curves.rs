//! The curves a layer holds, and the curve each basis draws through its points.

use glam::Vec3;

/// A curve set's `type`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CurveType {
    /// Straight segments between the points.
    Linear,
    /// Cubic segments in the curve set's [`CurveBasis`].
    Cubic,
}

/// A cubic curve set's `basis`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CurveBasis {
    /// Four points a segment, the last shared with the next.
    Bezier,
    /// Uniform cubic B-spline.
    Bspline,
    /// Catmull-Rom: through every point but the first and last (unless pinned).
    CatmullRom,
}

/// A curve set's `wrap`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CurveWrap {
    /// Open curves.
    Nonperiodic,
    /// Closed curves.
    Periodic,
    /// Open curves that start and end at their first and last points.
    Pinned,
}

/// One `BasisCurves` prim.
#[derive(Clone, Debug, PartialEq)]
pub struct Curves {
    /// The prim's path (`/Fur/Strands`).
    pub path: String,
    /// Points per curve.
    pub counts: Vec<u32>,
    /// Every curve's points in the stage's space (its prims' transforms applied), curve after
    /// curve.
    pub points: Vec<Vec3>,
    /// `type`.
    pub curve_type: CurveType,
    /// `basis`.
    pub basis: CurveBasis,
    /// `wrap`.
    pub wrap: CurveWrap,
    /// One linear RGB colour per curve from `primvars:displayColor` (a constant colour repeated,
    /// a per-vertex one read at each curve's first point), if it has one.
    pub colours: Option<Vec<Vec3>>,
    /// Each curve's length over its column's (`primvars:pelt:lengthFactor`, uniform), as Pelt
    /// writes it: a coat's strands end at seeded heights, and this says where.
    pub length_factors: Option<Vec<f32>>,
    /// What Pelt's shell texture added to each point (`primvars:pelt:textureOffset`, vertex),
    /// in the stage's space like the points: a point less its offset lies on the strand's
    /// column, which the groom alone shapes.
    pub texture_offsets: Option<Vec<Vec3>>,
}

impl Curves {
    /// The points of curve `k` (needs `offsets`: each curve's first point, see [`Self::offsets`]).
    #[must_use]
    pub fn curve<'a>(&'a self, offsets: &[usize], k: usize) -> &'a [Vec3] {
        &self.points[offsets[k]..offsets[k] + self.counts[k] as usize]
    }

    /// Each curve's first point's index in [`Self::points`].
    #[must_use]
    pub fn offsets(&self) -> Vec<usize> {
        let mut at = 0;
        self.counts
            .iter()
            .map(|&n| {
                let first = at;
                at += n as usize;
                first
            })
            .collect()
    }

    /// Samples along curve `points` where this set draws it (cubic segments at `per_segment`
    /// points each, linear ones at their points).
    #[must_use]
    pub fn polyline(&self, points: &[Vec3], per_segment: usize) -> Vec<Vec3> {
        polyline(points, self.curve_type, self.basis, self.wrap, per_segment)
    }
}

/// One colour per curve from `primvars:displayColor`'s values and interpolation.
pub(super) fn curve_colours(colours: &[Vec3], interpolation: &str, counts: &[u32]) -> Result<Vec<Vec3>, String> {
    if colours.iter().any(|c| !c.is_finite()) {
        return Err("primvars:displayColor must be finite (r, g, b) triples".to_owned());
    }
    let wrong = |expected: usize| {
        format!(
            "primvars:displayColor has {} colours, but {interpolation} interpolation needs {expected}",
            colours.len()
        )
    };
    match interpolation {
        "constant" => colours.first().map(|c| vec![*c; counts.len()]).ok_or_else(|| wrong(1)),
        "uniform" if colours.len() == counts.len() => Ok(colours.to_vec()),
        "uniform" => Err(wrong(counts.len())),
        "vertex" | "varying" => {
            let total: usize = counts.iter().map(|&n| n as usize).sum();
            if colours.len() != total {
                // Varying counts segment ends; take each curve's first colour either way.
                if interpolation == "vertex" {
                    return Err(wrong(total));
                }
            }
            let mut at = 0usize;
            let mut out = Vec::with_capacity(counts.len());
            for &n in counts {
                out.push(*colours.get(at).ok_or_else(|| wrong(total))?);
                at += if colours.len() == total { n as usize } else { (colours.len() / counts.len()).max(1) };
            }
            Ok(out)
        }
        other => Err(format!("primvars:displayColor: unknown interpolation {other:?}")),
    }
}

/// The drawn curve through `points` as a polyline.
pub(super) fn polyline(
    points: &[Vec3],
    curve_type: CurveType,
    basis: CurveBasis,
    wrap: CurveWrap,
    per_segment: usize,
) -> Vec<Vec3> {
    let n = points.len();
    if curve_type == CurveType::Linear || n < 2 {
        let mut out = points.to_vec();
        if wrap == CurveWrap::Periodic && n > 2 {
            out.push(points[0]);
        }
        return out;
    }
    let per_segment = per_segment.max(1);
    let at = |k: isize| -> Vec3 {
        match wrap {
            CurveWrap::Periodic => points[k.rem_euclid(n as isize) as usize],
            // Pinned curves extend past their ends by reflection, so they start and end there.
            _ if k < 0 => points[0] * 2.0 - points[1],
            _ if k >= n as isize => points[n - 1] * 2.0 - points[n - 2],
            _ => points[k as usize],
        }
    };
    let mut out = Vec::new();
    match basis {
        CurveBasis::Bezier => {
            let segments = if wrap == CurveWrap::Periodic { n / 3 } else { (n - 1) / 3 };
            for s in 0..segments {
                let [p0, p1, p2, p3] = [0, 1, 2, 3].map(|k| at((3 * s + k) as isize));
                for k in usize::from(s > 0)..=per_segment {
                    let t = k as f32 / per_segment as f32;
                    let u = 1.0 - t;
                    out.push(p0 * (u * u * u) + p1 * (3.0 * u * u * t) + p2 * (3.0 * u * t * t) + p3 * (t * t * t));
                }
            }
        }
        CurveBasis::Bspline | CurveBasis::CatmullRom => {
            let (first, segments): (isize, isize) = match wrap {
                CurveWrap::Periodic => (0, n as isize),
                CurveWrap::Pinned => (-1, n as isize - 1),
                CurveWrap::Nonperiodic => (0, n as isize - 3),
            };
            for s in 0..segments {
                let [p0, p1, p2, p3] = [0, 1, 2, 3].map(|k| at(first + s + k));
                for k in usize::from(s > 0)..=per_segment {
                    let t = k as f32 / per_segment as f32;
                    let (t2, t3) = (t * t, t * t * t);
                    out.push(if basis == CurveBasis::Bspline {
                        (p0 * (1.0 - t).powi(3)
                            + p1 * (3.0 * t3 - 6.0 * t2 + 4.0)
                            + p2 * (-3.0 * t3 + 3.0 * t2 + 3.0 * t + 1.0)
                            + p3 * t3)
                            / 6.0
                    } else {
                        (p1 * 2.0
                            + (p2 - p0) * t
                            + (p0 * 2.0 - p1 * 5.0 + p2 * 4.0 - p3) * t2
                            + (p1 * 3.0 - p0 - p2 * 3.0 + p3) * t3)
                            * 0.5
                    });
                }
            }
        }
    }
    out
}
