//! A fur's skin planes and triangles, found once per rest shape in a process.
//!
//! Finding them is the costly part of a simulation's setup on a dense mesh, and a host makes
//! several simulations of one fur (its own, the GPU kernel's buffers, the timings that choose
//! a kernel): they share one result, looked up by the exact rest shape it was found from.

use std::sync::{Arc, Mutex};

use glam::{Vec3, Vec4};

use super::skin::{SKIN_PLANES, skin_planes_of};
use super::surface::{SkinSurface, skin_surface};
use crate::fur::FurStructure;

/// Every strand's skin planes and the triangles kept where they fall short.
#[derive(Debug, PartialEq)]
pub struct SkinSetup {
    /// The cell the planes' faces were ordered by (`skin_planes_of`).
    pub cell: f32,
    /// Every strand's planes ([`skin_planes`](super::skin_planes)).
    pub planes: Vec<[Vec4; SKIN_PLANES]>,
    /// The triangles of the strands whose planes fall short ([`skin_surface`]).
    pub surface: SkinSurface,
}

/// What the setup is a function of, kept whole so a hit is an exact match.
#[derive(PartialEq)]
struct Key {
    layers: u32,
    positions: Vec<Vec3>,
    mesh_positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
}

impl Key {
    fn matches(&self, fur: &FurStructure) -> bool {
        self.layers == fur.layers
            && self.positions == fur.positions
            && self.mesh_positions == fur.mesh.positions
            && self.normals == fur.mesh.normals
            && self.triangles == fur.mesh.triangles
    }
}

/// The last few setups found (a host rarely keeps more furs than this in setup at once).
static RECENT: Mutex<Vec<(Key, Arc<SkinSetup>)>> = Mutex::new(Vec::new());
const KEPT: usize = 2;

/// `fur`'s skin setup: [`skin_planes`](super::skin_planes) and [`skin_surface`] of it, shared
/// with every earlier call for the same rest shape.
#[must_use]
pub fn skin_setup(fur: &FurStructure) -> Arc<SkinSetup> {
    // A poisoned lock only means another thread panicked mid-lookup: the list is still whole.
    let recent = || RECENT.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    if let Some((_, setup)) = recent().iter().find(|(key, _)| key.matches(fur)) {
        return setup.clone();
    }
    // Found outside the lock: another fur's setup may go on meanwhile.
    let (cell, planes) = skin_planes_of(fur, 0..fur.vertex_count());
    let surface = skin_surface(fur, &planes);
    let setup = Arc::new(SkinSetup { cell, planes, surface });
    let key = Key {
        layers: fur.layers,
        positions: fur.positions.clone(),
        mesh_positions: fur.mesh.positions.clone(),
        normals: fur.mesh.normals.clone(),
        triangles: fur.mesh.triangles.clone(),
    };
    let mut list = recent();
    list.insert(0, (key, setup.clone()));
    list.truncate(KEPT);
    setup
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fur::{FurLength, FurParams, GrowthDirection};
    use crate::mesh::builtin::Builtin;
    use crate::sim::contact::skin_planes;

    /// A shared setup is the one found afresh, and another rest shape gets its own.
    #[test]
    fn a_shared_setup_equals_a_fresh_one() {
        let (mesh, _) = Builtin::Torus.mesh();
        let grow = |length| {
            let params =
                FurParams { layers: 6, length: FurLength::Constant(length), direction: GrowthDirection::default() };
            FurStructure::new(mesh.clone(), &params).unwrap()
        };
        let (short, long) = (grow(0.2), grow(0.4));
        let first = skin_setup(&short);
        assert_eq!(*skin_setup(&short), *first);
        let planes = skin_planes(&long);
        let other = skin_setup(&long);
        assert!(!Arc::ptr_eq(&first, &other));
        assert_eq!(other.planes, planes);
        assert_eq!(other.surface, skin_surface(&long, &planes));
    }
}
