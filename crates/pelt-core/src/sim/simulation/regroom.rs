//! A groom dab on a running simulation: the strands it reshaped take their new rest shape and
//! skin planes in place, so painting never rebuilds the simulation (the skin planes of every
//! strand are most of [`Simulation::new`]'s cost).

use super::{SimError, Simulation, skin_lanes, skin_planes_of};
use crate::fur::FurStructure;
use crate::sim::contact::surface::skin_surface_of;

impl Simulation {
    /// Takes `fur`'s rest shape for `strands` (the base vertices whose length or direction a
    /// groom edit changed; `fur` is this simulation's structure regrown, same mesh and `L`),
    /// and restarts from the current base and time as a new simulation would. Every other
    /// setting (wind, field, stability, wetness, colliders, pose) stays. The rest shape and skin
    /// planes are those [`Simulation::new`] makes from `fur`, to the bit.
    ///
    /// # Errors
    /// [`SimError::Size`] for a structure of another vertex count or layer count, or a strand
    /// index past its vertices.
    pub fn regroom(&mut self, fur: &FurStructure, strands: &[u32]) -> Result<(), SimError> {
        let v = self.vertex_count;
        let layers = self.layers as usize;
        if fur.layers != self.layers || fur.vertex_count() != v || fur.positions.len() != v * (layers + 1) {
            return Err(SimError::Size {
                what: "the regroomed shared vertex array",
                expected: v * (layers + 1),
                got: fur.positions.len(),
            });
        }
        if let Some(&bad) = strands.iter().find(|&&j| j as usize >= v) {
            return Err(SimError::Size { what: "the regroomed strands' indices", expected: v, got: bad as usize + 1 });
        }
        if strands.is_empty() {
            return Ok(());
        }
        self.rest.update(&fur.positions, v, layers, strands);
        if let Some(source) = &mut self.skin_source {
            // Skin contact is off: only the rest shape its setup will be found from changes.
            source.positions.clone_from(&fur.positions);
            self.restart();
            return Ok(());
        }
        let (cell, planes) = skin_planes_of(fur, strands.iter().map(|&j| j as usize));
        if cell.to_bits() == self.skin_cell.to_bits() {
            for (&j, planes) in strands.iter().zip(planes) {
                self.skin[j as usize] = planes;
            }
            self.surface = skin_surface_of(&self.surface, fur, &self.skin, strands);
        } else {
            // The longest strand changed: the grid, and so any strand's tie order, with it. The
            // skin triangles are found again for the strands whose planes moved too.
            let (cell, all) = skin_planes_of(fur, 0..v);
            let bits =
                |planes: &[glam::Vec4]| planes.iter().flat_map(|p| p.to_array().map(f32::to_bits)).collect::<Vec<_>>();
            let mut changed: Vec<u32> = strands.to_vec();
            changed.extend((0..v).filter(|&j| bits(&self.skin[j]) != bits(&all[j])).map(|j| j as u32));
            changed.sort_unstable();
            changed.dedup();
            (self.skin_cell, self.skin) = (cell, all);
            self.surface = skin_surface_of(&self.surface, fur, &self.skin, &changed);
        }
        self.skin_lanes = skin_lanes(&self.skin);
        self.restart();
        Ok(())
    }
}
