//! The force field (one vector per base vertex) and the touch that overrides it near a hit.
//!
//! A touch never writes into the [`ForceField`]: it is an overlay applied when the external field
//! is evaluated, so ending it gives back the original values bit for bit.

use glam::Vec3;

/// One force vector per base vertex, added to gravity and wind (zero by default). Applications
/// paint or script their own forces here; the touch and wind leave it untouched.
#[derive(Clone, Debug, PartialEq)]
pub struct ForceField {
    values: Vec<Vec3>,
}

impl ForceField {
    /// A zero field over `vertex_count` base vertices.
    #[must_use]
    pub fn new(vertex_count: usize) -> Self {
        Self { values: vec![Vec3::ZERO; vertex_count] }
    }

    /// The forces, one per base vertex.
    #[must_use]
    pub fn values(&self) -> &[Vec3] {
        &self.values
    }

    /// The forces, to edit in place. Non-finite values are treated as no force by the simulation.
    pub fn values_mut(&mut self) -> &mut [Vec3] {
        &mut self.values
    }

    /// Sets every vertex to `force`.
    pub fn fill(&mut self, force: Vec3) {
        self.values.fill(force);
    }

    /// Number of base vertices.
    #[must_use]
    pub fn len(&self) -> usize {
        self.values.len()
    }

    /// Whether the field covers no vertex.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }
}

/// A touch (patting): the pointer hit the fur at `point` and has been dragged to `drag`. Within
/// `radius` of the hit, the field is replaced by the interaction force with a smooth falloff.
#[derive(Clone, Debug, PartialEq)]
pub struct Touch {
    /// Where the touch began (on or near the base surface).
    pub point: Vec3,
    /// Radius of influence (world units).
    pub radius: f32,
    /// Where the pointer is now; the interaction vector is `drag - point`.
    pub drag: Vec3,
    /// When the touch ended (simulation time), if it has.
    pub released_at_secs: Option<f64>,
    /// Affected base vertices and their falloff weights in `(0, 1]`, in vertex order.
    weights: Vec<(u32, f32)>,
}

impl Touch {
    /// A touch at `point` over the base vertices `roots` (positions of the base mesh).
    #[must_use]
    pub fn new(point: Vec3, radius: f32, roots: &[Vec3]) -> Self {
        let weights = roots
            .iter()
            .enumerate()
            .filter_map(|(j, root)| {
                let weight = falloff(root.distance(point) / radius);
                (weight > 0.0).then_some((j as u32, weight))
            })
            .collect();
        Self { point, radius, drag: point, released_at_secs: None, weights }
    }

    /// `drag - point`.
    #[must_use]
    pub fn interaction(&self) -> Vec3 {
        self.drag - self.point
    }

    /// Affected base vertices with their falloff weights.
    #[must_use]
    pub fn weights(&self) -> &[(u32, f32)] {
        &self.weights
    }

    /// How much of the touch still acts at `time_secs`: 1 while held, then falling linearly to 0
    /// over `release_secs` after release (0 at once when `release_secs` is 0).
    #[must_use]
    pub fn presence(&self, time_secs: f64, release_secs: f32) -> f32 {
        match self.released_at_secs {
            None => 1.0,
            Some(_) if release_secs <= 0.0 => 0.0,
            Some(released) => (1.0 - ((time_secs - released) / f64::from(release_secs)) as f32).clamp(0.0, 1.0),
        }
    }

    /// Replaces `field` near the hit: `field * (1 - w) + force * w` with `w` the falloff times
    /// `presence`, and `force = interaction / radius * strength`. Vertices outside the radius,
    /// and all of them at zero presence, keep their values exactly.
    pub fn apply(&self, strength: f32, presence: f32, field: &mut [Vec3]) {
        self.blend(self.force(strength), presence, field);
    }

    /// The touch's force for the touch parameter `strength`: `interaction / radius * strength`.
    #[must_use]
    pub fn force(&self, strength: f32) -> Vec3 {
        self.interaction() / self.radius * strength
    }

    /// [`Touch::apply`] with its [`Touch::force`] given.
    pub fn blend(&self, force: Vec3, presence: f32, field: &mut [Vec3]) {
        if presence <= 0.0 {
            return;
        }
        for &(j, weight) in &self.weights {
            let w = weight * presence;
            let value = &mut field[j as usize];
            *value = *value * (1.0 - w) + force * w;
        }
    }
}

/// Smooth falloff over a normalised distance: 1 at the centre, 0 from 1 on, zero slope at both.
fn falloff(distance: f32) -> f32 {
    if distance.is_nan() || distance >= 1.0 {
        return 0.0;
    }
    let t = 1.0 - distance * distance;
    t * t
}
