//! The one k-d tree of the project: an incremental index for nearest-neighbour search (k = 1,
//! Euclidean), used by the explorers' meta-policy (the outcome nearest to a goal) and by the
//! discovery measures (the distance from each test goal to the nearest outcome).
//!
//! Points are inserted one at a time (no rebuild); exact duplicates are stored once, so a history
//! in which thousands of episodes left the object where it was stays shallow. Ties are broken
//! towards the earliest inserted point, which makes the search deterministic.

use std::collections::HashMap;

const NONE: u32 = u32::MAX;

#[derive(Clone, Copy, Debug)]
struct Node {
    point: u32,
    axis: u32,
    left: u32,
    right: u32,
}

/// Incremental nearest-neighbour index over points of a fixed dimension.
#[derive(Clone, Debug)]
pub struct NnIndex {
    dim: usize,
    coords: Vec<f64>,
    nodes: Vec<Node>,
    /// First index of each distinct point (by bit pattern, -0.0 folded into 0.0).
    first: HashMap<Box<[u64]>, u32>,
    /// For each inserted point, the storage slot of its coordinates (shared by duplicates).
    canonical: Vec<u32>,
    /// For each storage slot, the index of the first insertion of that point.
    owner: Vec<u32>,
}

impl NnIndex {
    /// An empty index for points of dimension `dim` (> 0).
    pub fn new(dim: usize) -> Self {
        assert!(dim > 0, "NnIndex dimension must be positive");
        NnIndex {
            dim,
            coords: Vec::new(),
            nodes: Vec::new(),
            first: HashMap::new(),
            canonical: Vec::new(),
            owner: Vec::new(),
        }
    }

    /// Dimension of the points.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// Number of points inserted (duplicates included).
    pub fn len(&self) -> usize {
        self.canonical.len()
    }

    /// Whether nothing has been inserted.
    pub fn is_empty(&self) -> bool {
        self.canonical.is_empty()
    }

    /// Number of distinct points.
    pub fn n_distinct(&self) -> usize {
        self.nodes.len()
    }

    /// The coordinates of the `i`-th inserted point.
    pub fn point(&self, i: usize) -> &[f64] {
        let c = self.canonical[i] as usize;
        &self.coords[c * self.dim..(c + 1) * self.dim]
    }

    /// Insert a point; returns its index (the number of points inserted before it).
    ///
    /// Panics if the point has the wrong dimension or a NaN coordinate (callers check outcomes).
    pub fn insert(&mut self, p: &[f64]) -> usize {
        assert_eq!(p.len(), self.dim, "point dimension");
        assert!(
            p.iter().all(|v| !v.is_nan()),
            "NaN coordinate inserted into NnIndex"
        );
        let idx = self.canonical.len() as u32;
        let key: Box<[u64]> = p.iter().map(|v| (v + 0.0).to_bits()).collect();
        if let Some(&f) = self.first.get(&key) {
            let slot = self.canonical[f as usize];
            self.canonical.push(slot);
            return idx as usize;
        }
        self.first.insert(key, idx);
        let slot = (self.coords.len() / self.dim) as u32;
        self.coords.extend_from_slice(p);
        self.canonical.push(slot);
        let node_id = self.nodes.len() as u32;
        let mut axis = 0u32;
        if !self.nodes.is_empty() {
            let mut cur = 0usize;
            loop {
                let n = self.nodes[cur];
                let split = self.coords[n.point as usize * self.dim + n.axis as usize];
                let go_left = p[n.axis as usize] < split;
                let next = if go_left { n.left } else { n.right };
                if next == NONE {
                    if go_left {
                        self.nodes[cur].left = node_id;
                    } else {
                        self.nodes[cur].right = node_id;
                    }
                    axis = (n.axis + 1) % self.dim as u32;
                    break;
                }
                cur = next as usize;
            }
        }
        self.nodes.push(Node {
            point: slot,
            axis,
            left: NONE,
            right: NONE,
        });
        self.owner.push(idx);
        idx as usize
    }

    /// The nearest inserted point to `q`: (index of its earliest insertion, squared distance).
    pub fn nearest(&self, q: &[f64]) -> Option<(usize, f64)> {
        assert_eq!(q.len(), self.dim, "query dimension");
        if self.nodes.is_empty() {
            return None;
        }
        let d = self.dim;
        let mut best = (f64::INFINITY, u32::MAX);
        let mut stack: Vec<(u32, f64)> = Vec::with_capacity(64);
        stack.push((0, 0.0));
        while let Some((id, bound)) = stack.pop() {
            if bound > best.0 {
                continue;
            }
            let n = self.nodes[id as usize];
            let p = &self.coords[n.point as usize * d..(n.point as usize + 1) * d];
            let mut d2 = 0.0;
            for k in 0..d {
                let t = p[k] - q[k];
                d2 += t * t;
            }
            let owner = self.owner[n.point as usize];
            if d2 < best.0 || (d2 == best.0 && owner < best.1) {
                best = (d2, owner);
            }
            let diff = q[n.axis as usize] - p[n.axis as usize];
            let (near, far) = if diff < 0.0 {
                (n.left, n.right)
            } else {
                (n.right, n.left)
            };
            // Push the far side first so the near side is explored first.
            if far != NONE {
                stack.push((far, diff * diff));
            }
            if near != NONE {
                stack.push((near, 0.0));
            }
        }
        Some((best.1 as usize, best.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small xorshift stream: the tests need spread points, not a particular generator.
    struct Xorshift(u64);

    impl Xorshift {
        fn random_range(&mut self, r: std::ops::Range<f64>) -> f64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            r.start + (r.end - r.start) * (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    fn brute(points: &[Vec<f64>], q: &[f64]) -> (usize, f64) {
        let mut best = (usize::MAX, f64::INFINITY);
        for (i, p) in points.iter().enumerate() {
            let d2: f64 = p.iter().zip(q).map(|(a, b)| (a - b) * (a - b)).sum();
            if d2 < best.1 {
                best = (i, d2);
            }
        }
        best
    }

    #[test]
    fn matches_brute_force_with_duplicates() {
        let mut rng = Xorshift(0x9E37_79B9_7F4A_7C15);
        for dim in [1, 2, 3, 10] {
            let mut idx = NnIndex::new(dim);
            let mut pts = Vec::new();
            for i in 0..2000 {
                // A third of the points are one repeated value, like unmoved outcomes.
                let p: Vec<f64> = if i % 3 == 0 {
                    vec![0.8; dim]
                } else {
                    (0..dim).map(|_| rng.random_range(0.0..1.0)).collect()
                };
                assert_eq!(idx.insert(&p), i);
                pts.push(p);
                if i % 97 == 0 {
                    for _ in 0..20 {
                        let q: Vec<f64> = (0..dim).map(|_| rng.random_range(-0.2..1.2)).collect();
                        let (bi, bd) = brute(&pts, &q);
                        let (ni, nd) = idx.nearest(&q).unwrap();
                        assert_eq!(nd, bd);
                        assert_eq!(ni, bi, "dim {dim}");
                    }
                }
            }
            assert_eq!(idx.len(), 2000);
            assert!(idx.n_distinct() <= 1334);
            // The duplicated point resolves to its first insertion.
            assert_eq!(idx.nearest(&vec![0.8; dim]).unwrap(), (0, 0.0));
            assert_eq!(idx.point(3), &vec![0.8; dim][..]);
        }
    }

    #[test]
    fn empty_index() {
        assert!(NnIndex::new(2).nearest(&[0.0, 0.0]).is_none());
    }
}
