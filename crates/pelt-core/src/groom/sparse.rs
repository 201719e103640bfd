//! The normal equations of a least-squares fit over a mesh's vertices: a symmetric matrix with
//! the mesh's one-ring sparsity, solved by conjugate gradients.

use crate::mesh::Mesh;

/// A symmetric matrix over the mesh's vertices with one-ring sparsity (rows of sorted columns).
pub(super) struct Sparse {
    starts: Vec<usize>,
    columns: Vec<u32>,
    values: Vec<f64>,
}

impl Sparse {
    pub(super) fn new(mesh: &Mesh) -> Self {
        let v = mesh.vertex_count();
        let mut rows: Vec<Vec<u32>> = (0..v as u32).map(|j| vec![j]).collect();
        for t in &mesh.triangles {
            for &a in t {
                rows[a as usize].extend_from_slice(t);
            }
        }
        let mut starts = Vec::with_capacity(v + 1);
        let mut columns = Vec::new();
        for row in &mut rows {
            row.sort_unstable();
            row.dedup();
            starts.push(columns.len());
            columns.extend_from_slice(row);
        }
        starts.push(columns.len());
        let values = vec![0.0; columns.len()];
        Self { starts, columns, values }
    }

    fn slot(&self, row: u32, column: u32) -> usize {
        let (start, end) = (self.starts[row as usize], self.starts[row as usize + 1]);
        let at = self.columns[start..end].binary_search(&column).expect("triangle corners share a one-ring row");
        start + at
    }

    pub(super) fn add(&mut self, row: u32, column: u32, value: f64) {
        let slot = self.slot(row, column);
        self.values[slot] += value;
    }

    pub(super) fn add_diagonal(&mut self, j: usize, value: f64) {
        self.add(j as u32, j as u32, value);
    }

    fn multiply(&self, x: &[f64], out: &mut [f64]) {
        for (row, out) in out.iter_mut().enumerate() {
            let (start, end) = (self.starts[row], self.starts[row + 1]);
            *out = (start..end).map(|k| self.values[k] * x[self.columns[k] as usize]).sum();
        }
    }

    /// Jacobi-preconditioned conjugate gradients (the matrix is symmetric positive definite).
    pub(super) fn solve(&self, b: &[f64]) -> Vec<f64> {
        let n = b.len();
        let diagonal: Vec<f64> = (0..n).map(|j| self.values[self.slot(j as u32, j as u32)].max(1e-12)).collect();
        let mut x = vec![0.0; n];
        let mut r = b.to_vec();
        let mut z: Vec<f64> = r.iter().zip(&diagonal).map(|(r, d)| r / d).collect();
        let mut p = z.clone();
        let mut rz: f64 = r.iter().zip(&z).map(|(a, b)| a * b).sum();
        let norm_b = b.iter().map(|x| x * x).sum::<f64>().sqrt().max(1e-30);
        let mut q = vec![0.0; n];
        for _ in 0..(4 * n).max(50) {
            if r.iter().map(|x| x * x).sum::<f64>().sqrt() <= 1e-10 * norm_b {
                break;
            }
            self.multiply(&p, &mut q);
            let pq: f64 = p.iter().zip(&q).map(|(a, b)| a * b).sum();
            if pq.abs() < 1e-300 {
                break;
            }
            let alpha = rz / pq;
            for k in 0..n {
                x[k] += alpha * p[k];
                r[k] -= alpha * q[k];
            }
            for k in 0..n {
                z[k] = r[k] / diagonal[k];
            }
            let next: f64 = r.iter().zip(&z).map(|(a, b)| a * b).sum();
            let beta = next / rz;
            rz = next;
            for k in 0..n {
                p[k] = z[k] + beta * p[k];
            }
        }
        x
    }
}
