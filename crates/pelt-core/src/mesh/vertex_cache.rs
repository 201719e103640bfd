//! Triangle order for the vertex cache: Tipsify (Sander, Nehab and Barczak 2007, "Fast Triangle
//! Reordering for Vertex Locality and Reduced Overdraw"), linear in the number of triangles.
//!
//! Why: the shells draw every base triangle once per layer through an index buffer, and both GPUs
//! and software rasterisers shade an indexed vertex again whenever it has left their small
//! vertex cache (lavapipe keeps 256 entries, reset every 1,024 indices). Meshes as exported are
//! often in no useful order: the Stanford bunny's triangles had its vertices shaded 3.0 times
//! each per layer, 1.3 times after this order.

/// The vertex cache size the order is tuned for (GPUs' post-transform caches hold 16 to 32
/// entries; the order is good for larger caches too).
pub(super) const CACHE_SIZE: u32 = 16;

/// The order in which to draw `triangles` (indices into them, each once) so that each triangle
/// shares vertices with those just before it. Deterministic: the same mesh gives the same order.
pub(super) fn tipsify_order(triangles: &[[u32; 3]], vertex_count: usize, cache_size: u32) -> Vec<u32> {
    // The triangles around each vertex, as offsets into one list.
    let mut offsets = vec![0u32; vertex_count + 1];
    for triangle in triangles {
        for &v in triangle {
            offsets[v as usize + 1] += 1;
        }
    }
    for v in 0..vertex_count {
        offsets[v + 1] += offsets[v];
    }
    let mut filled = offsets.clone();
    let mut around = vec![0u32; triangles.len() * 3];
    for (t, triangle) in triangles.iter().enumerate() {
        for &v in triangle {
            around[filled[v as usize] as usize] = t as u32;
            filled[v as usize] += 1;
        }
    }
    // Triangles not yet emitted around each vertex.
    let mut live: Vec<u32> = (0..vertex_count).map(|v| offsets[v + 1] - offsets[v]).collect();
    // When each vertex last entered the simulated cache; `time - cached[v] > cache_size` means
    // it has left it (all have at the start).
    let mut cached = vec![0u32; vertex_count];
    let mut time = cache_size + 1;
    let mut emitted = vec![false; triangles.len()];
    let mut order = Vec::with_capacity(triangles.len());
    // Vertices of emitted triangles, newest last: where to go on from a dead end.
    let mut dead_ends: Vec<u32> = Vec::new();
    let mut cursor = 0usize;
    // This fan's vertices, in the order they were met (a list, not a set, for determinism), and
    // the last fan each vertex joined (so a vertex with thousands of triangles costs no search).
    let mut candidates: Vec<u32> = Vec::new();
    let mut in_fan = vec![u32::MAX; vertex_count];
    let mut fan = next_live(&live, &mut dead_ends, &mut cursor);
    while let Some(f) = fan {
        candidates.clear();
        for &t in &around[offsets[f as usize] as usize..offsets[f as usize + 1] as usize] {
            if emitted[t as usize] {
                continue;
            }
            emitted[t as usize] = true;
            order.push(t);
            for &v in &triangles[t as usize] {
                dead_ends.push(v);
                if in_fan[v as usize] != f {
                    in_fan[v as usize] = f;
                    candidates.push(v);
                }
                live[v as usize] -= 1;
                if time - cached[v as usize] > cache_size {
                    cached[v as usize] = time;
                    time += 1;
                }
            }
        }
        // The next fan: the candidate longest in the cache that will still be in it after its
        // remaining triangles (each adds up to two vertices), else a dead end's way out.
        let mut best: Option<(u32, u32)> = None;
        for &v in &candidates {
            if live[v as usize] == 0 {
                continue;
            }
            let age = time - cached[v as usize];
            let priority = if age + 2 * live[v as usize] <= cache_size { age } else { 0 };
            if best.is_none_or(|(_, p)| priority > p) {
                best = Some((v, priority));
            }
        }
        fan = match best {
            Some((v, _)) => Some(v),
            None => next_live(&live, &mut dead_ends, &mut cursor),
        };
    }
    order
}

/// A vertex that still has triangles to emit: the most recent dead end, else the next in index
/// order from `cursor`; `None` when every triangle is out.
fn next_live(live: &[u32], dead_ends: &mut Vec<u32>, cursor: &mut usize) -> Option<u32> {
    while let Some(v) = dead_ends.pop() {
        if live[v as usize] > 0 {
            return Some(v);
        }
    }
    while *cursor < live.len() {
        if live[*cursor] > 0 {
            return Some(*cursor as u32);
        }
        *cursor += 1;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Vertices shaded by a first-in-first-out cache of `size` entries, per triangle (the
    /// "average cache miss ratio"; an oracle apart from the order's own simulation).
    fn fifo_misses_per_triangle(triangles: &[[u32; 3]], size: usize) -> f64 {
        let mut cache = std::collections::VecDeque::new();
        let mut misses = 0;
        for &v in triangles.iter().flatten() {
            if !cache.contains(&v) {
                misses += 1;
                cache.push_back(v);
                if cache.len() > size {
                    cache.pop_front();
                }
            }
        }
        f64::from(misses) / triangles.len() as f64
    }

    /// A grid of `n` x `n` quads with its triangles shuffled.
    fn shuffled_grid(n: u32) -> Vec<[u32; 3]> {
        let mut triangles = Vec::new();
        for y in 0..n {
            for x in 0..n {
                let v = |dx: u32, dy: u32| (y + dy) * (n + 1) + x + dx;
                triangles.push([v(0, 0), v(1, 0), v(1, 1)]);
                triangles.push([v(0, 0), v(1, 1), v(0, 1)]);
            }
        }
        let mut state = 0x2545_f491_u32;
        for i in (1..triangles.len()).rev() {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            triangles.swap(i, state as usize % (i + 1));
        }
        triangles
    }

    #[test]
    fn every_triangle_comes_out_once_and_shares_the_cache() {
        let n = 40;
        let triangles = shuffled_grid(n);
        let order = tipsify_order(&triangles, ((n + 1) * (n + 1)) as usize, CACHE_SIZE);
        let mut seen = order.clone();
        seen.sort_unstable();
        assert_eq!(seen, (0..triangles.len() as u32).collect::<Vec<_>>());
        let reordered: Vec<[u32; 3]> = order.iter().map(|&t| triangles[t as usize]).collect();
        let before = fifo_misses_per_triangle(&triangles, 32);
        let after = fifo_misses_per_triangle(&reordered, 32);
        // A regular grid can reach about 0.5 (each vertex shaded once); shuffled it is near 3.
        assert!(before > 2.5, "shuffled grid: {before}");
        assert!(after < 0.8, "reordered grid: {after} misses per triangle");
        assert_eq!(order, tipsify_order(&triangles, ((n + 1) * (n + 1)) as usize, CACHE_SIZE));
    }

    #[test]
    fn a_vertex_with_a_huge_fan_comes_out_whole() {
        // A disc of 200,000 triangles around vertex 0 (a search of the fan's vertices for each
        // new one would make this quadratic: minutes instead of milliseconds).
        let n = 200_000u32;
        let triangles: Vec<[u32; 3]> = (0..n).map(|i| [0, 1 + i, 1 + (i + 1) % n]).collect();
        let mut order = tipsify_order(&triangles, n as usize + 1, CACHE_SIZE);
        order.sort_unstable();
        assert_eq!(order, (0..n).collect::<Vec<_>>());
    }

    #[test]
    fn vertices_without_triangles_and_tiny_meshes() {
        assert!(tipsify_order(&[], 5, CACHE_SIZE).is_empty());
        // Vertex 0 and 4 belong to no triangle.
        assert_eq!(tipsify_order(&[[1, 2, 3]], 5, CACHE_SIZE), vec![0]);
        let two = tipsify_order(&[[1, 2, 3], [3, 2, 4]], 5, CACHE_SIZE);
        assert_eq!(two.len(), 2);
    }
}
