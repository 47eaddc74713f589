//! Row-sparse storage of images: a rendered object covers ~100 of the 4900 pixels, so products
//! with the data matrix cost O(non-zeros) instead of O(n x 4900).

use super::ImageSet;

/// Compressed sparse rows (f64 values).
#[derive(Clone, Debug, PartialEq)]
pub struct SparseRows {
    pub n_rows: usize,
    pub n_cols: usize,
    pub indptr: Vec<usize>,
    pub indices: Vec<u32>,
    pub values: Vec<f64>,
}

impl SparseRows {
    /// From an image set (exact zeros dropped).
    pub fn from_images(images: &ImageSet) -> Self {
        let mut indptr = Vec::with_capacity(images.n + 1);
        let (mut indices, mut values) = (Vec::new(), Vec::new());
        indptr.push(0);
        for i in 0..images.n {
            for (j, &v) in images.row(i).iter().enumerate() {
                if v != 0.0 {
                    indices.push(j as u32);
                    values.push(v as f64);
                }
            }
            indptr.push(indices.len());
        }
        SparseRows {
            n_rows: images.n,
            n_cols: images.dim,
            indptr,
            indices,
            values,
        }
    }

    /// Row `i` as (column, value) pairs.
    pub fn row(&self, i: usize) -> impl Iterator<Item = (usize, f64)> + '_ {
        let r = self.indptr[i]..self.indptr[i + 1];
        self.indices[r.clone()]
            .iter()
            .map(|&c| c as usize)
            .zip(self.values[r].iter().copied())
    }

    /// `self (n x p) * b (p x k, row-major)` -> n x k row-major.
    pub fn mul_dense(&self, b: &[f64], k: usize) -> Vec<f64> {
        let mut out = vec![0.0; self.n_rows * k];
        for i in 0..self.n_rows {
            let o = &mut out[i * k..(i + 1) * k];
            for (c, v) in self.row(i) {
                let br = &b[c * k..(c + 1) * k];
                for t in 0..k {
                    o[t] += v * br[t];
                }
            }
        }
        out
    }

    /// `self^T (p x n) * b (n x k, row-major)` -> p x k row-major.
    pub fn tmul_dense(&self, b: &[f64], k: usize) -> Vec<f64> {
        let mut out = vec![0.0; self.n_cols * k];
        for i in 0..self.n_rows {
            let br = &b[i * k..(i + 1) * k];
            for (c, v) in self.row(i) {
                let o = &mut out[c * k..(c + 1) * k];
                for t in 0..k {
                    o[t] += v * br[t];
                }
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn products_match_dense() {
        let data: Vec<f32> = (0..12)
            .map(|i| if i % 3 == 0 { 0.0 } else { i as f32 * 0.1 })
            .collect();
        let set = ImageSet::new(3, 4, data.clone()).unwrap();
        let s = SparseRows::from_images(&set);
        let b: Vec<f64> = (0..8).map(|i| i as f64 - 3.0).collect(); // 4 x 2
        let got = s.mul_dense(&b, 2);
        for i in 0..3 {
            for t in 0..2 {
                let want: f64 = (0..4).map(|j| data[i * 4 + j] as f64 * b[j * 2 + t]).sum();
                assert!((got[i * 2 + t] - want).abs() < 1e-12);
            }
        }
        let c: Vec<f64> = (0..6).map(|i| i as f64 * 0.5).collect(); // 3 x 2
        let got = s.tmul_dense(&c, 2);
        for j in 0..4 {
            for t in 0..2 {
                let want: f64 = (0..3).map(|i| data[i * 4 + j] as f64 * c[i * 2 + t]).sum();
                assert!((got[j * 2 + t] - want).abs() < 1e-12);
            }
        }
    }
}
