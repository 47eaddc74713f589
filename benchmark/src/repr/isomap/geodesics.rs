//! Isomap's neighbourhood graph and geodesic distances: connecting its components as sklearn
//! does, and Dijkstra from every node on a CSR graph with a radix heap.

use super::*;

/// sklearn >= 1.0 `_fix_connected_components`: for every pair of components (ci > cj), the
/// closest pair (a in ci, b in cj) as (a, b, squared distance); ties go to the first pair in
/// (a, b) index order, like `argmin` over the row-major distance block. Work: every point of a
/// component against every point of the components before it.
pub(super) fn closest_pairs(
    index: &TrainIndex,
    images: &ImageSet,
    labels: &[u32],
    ncomp: usize,
) -> Vec<(u32, u32, f64)> {
    let n = images.n;
    // For each point a, the closest point of each earlier component (squared distance, b).
    let per_point: Vec<Vec<(f64, u32)>> = (0..n)
        .into_par_iter()
        .map_init(
            || (KnnScratch::new(n), vec![0.0f64; n]),
            |(s, d2), a| {
                let ca = labels[a] as usize;
                if ca == 0 {
                    return Vec::new();
                }
                distances_to_all(index, images, a, s, d2);
                let mut best = vec![(f64::INFINITY, u32::MAX); ca];
                for (b, &v) in d2.iter().enumerate() {
                    let cb = labels[b] as usize;
                    if cb < ca && v < best[cb].0 {
                        best[cb] = (v, b as u32);
                    }
                }
                best
            },
        )
        .collect();
    let mut best = vec![(f64::INFINITY, u32::MAX, u32::MAX); ncomp * ncomp];
    for (a, row) in per_point.iter().enumerate() {
        let ca = labels[a] as usize;
        for (cb, &(v, b)) in row.iter().enumerate() {
            // Points a come in increasing order: strict < keeps the first a on ties.
            if v < best[ca * ncomp + cb].0 {
                best[ca * ncomp + cb] = (v, a as u32, b);
            }
        }
    }
    let mut out = Vec::new();
    for ci in 0..ncomp {
        for cj in 0..ci {
            let (v, a, b) = best[ci * ncomp + cj];
            out.push((a, b, v));
        }
    }
    out
}

/// Squared distances from training image `a` to every training image.
pub(super) fn distances_to_all(
    index: &TrainIndex,
    images: &ImageSet,
    a: usize,
    s: &mut KnnScratch,
    d2: &mut [f64],
) {
    match index {
        TrainIndex::Sparse(idx) => {
            let x = images.row(a);
            let xn = idx.norms[a];
            idx.dots(
                x.iter()
                    .enumerate()
                    .filter(|(_, v)| **v != 0.0)
                    .map(|(p, &v)| (p, v)),
                s,
            );
            for (b, o) in d2.iter_mut().enumerate() {
                let dot = if s.stamp[b] == s.epoch { s.acc[b] } else { 0.0 };
                *o = clamp0((xn + idx.norms[b]) - 2.0 * dot);
            }
        }
        TrainIndex::Dense { data, norms } => {
            let dim = images.dim;
            let x = &data[a * dim..(a + 1) * dim];
            for (b, o) in d2.iter_mut().enumerate() {
                let y = &data[b * dim..(b + 1) * dim];
                let dot: f64 = x.iter().zip(y).map(|(&p, &q)| p as f64 * q as f64).sum();
                *o = clamp0((norms[a] + norms[b]) - 2.0 * dot);
            }
        }
    }
}

/// Undirected weighted graph in CSR form.
pub(super) struct Csr {
    pub(super) n: usize,
    pub(super) start: Vec<usize>,
    pub(super) adj: Vec<u32>,
    pub(super) w: Vec<f64>,
}

impl Csr {
    /// The undirected kNN graph (scipy `shortest_path(directed=False)` on sklearn's
    /// `kneighbors_graph(mode='distance')`): edge i-j when j is among i's neighbours or i among
    /// j's, weight the smaller of the two distances.
    pub(super) fn from_knn(n: usize, k: usize, knn: &[(f64, u32)]) -> Self {
        let mut edges: Vec<(u32, u32, f64)> = Vec::with_capacity(2 * n * k);
        for (i, nb) in knn.chunks(k).enumerate() {
            for &(d2, j) in nb {
                let w = d2.sqrt();
                edges.push((i as u32, j, w));
                edges.push((j, i as u32, w));
            }
        }
        Self::from_edges(n, edges)
    }

    /// From directed edge triples (both directions must be present for an undirected graph);
    /// parallel edges keep the smallest weight.
    pub(super) fn from_edges(n: usize, mut edges: Vec<(u32, u32, f64)>) -> Self {
        edges.sort_unstable_by(|a, b| a.0.cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.total_cmp(&b.2)));
        edges.dedup_by(|later, first| later.0 == first.0 && later.1 == first.1);
        let mut start = vec![0usize; n + 1];
        for e in &edges {
            start[e.0 as usize + 1] += 1;
        }
        for i in 0..n {
            start[i + 1] += start[i];
        }
        let adj = edges.iter().map(|e| e.1).collect();
        let w = edges.iter().map(|e| e.2).collect();
        Csr { n, start, adj, w }
    }

    /// Component label of every node (components numbered in order of their smallest node, as
    /// scipy's `connected_components`) and the component sizes.
    pub(super) fn components(&self) -> (Vec<u32>, Vec<usize>) {
        let mut label = vec![u32::MAX; self.n];
        let mut sizes = Vec::new();
        let mut stack = Vec::new();
        for s in 0..self.n {
            if label[s] != u32::MAX {
                continue;
            }
            let c = sizes.len() as u32;
            label[s] = c;
            stack.push(s as u32);
            let mut size = 0;
            while let Some(u) = stack.pop() {
                size += 1;
                for &v in &self.adj[self.start[u as usize]..self.start[u as usize + 1]] {
                    if label[v as usize] == u32::MAX {
                        label[v as usize] = c;
                        stack.push(v);
                    }
                }
            }
            sizes.push(size);
        }
        (label, sizes)
    }

    /// The directed edge triples (each undirected edge twice).
    pub(super) fn edges(&self) -> Vec<(u32, u32, f64)> {
        let mut e = Vec::with_capacity(self.adj.len());
        for i in 0..self.n {
            for q in self.start[i]..self.start[i + 1] {
                e.push((i as u32, self.adj[q], self.w[q]));
            }
        }
        e
    }

    /// Geodesic distances from every node, n x n row-major, accumulated in f64 and stored as
    /// f32. Nodes joined by exact zero-weight edges (identical images) are first merged: their
    /// distances to everything are equal (adding 0.0 is exact), so Dijkstra runs once per
    /// merged node on the merged graph (for 10,000 ball images at 4900 pixel positions, about
    /// 4,300 nodes: a 5x smaller all-pairs problem), and the rows are then expanded.
    pub(super) fn all_pairs(&self) -> Vec<f32> {
        let n = self.n;
        let (class, m) = self.zero_classes();
        let mut out = vec![0.0f32; n * n];
        if m == n {
            out.par_chunks_mut(n).enumerate().for_each_init(
                || (vec![0.0f64; n], vec![false; n], RadixHeap::new()),
                |(dist, done, heap), (s, row)| {
                    self.dijkstra(s, dist, done, heap);
                    for (o, &d) in row.iter_mut().zip(dist.iter()) {
                        *o = d as f32;
                    }
                },
            );
            return out;
        }
        let mut edges: Vec<(u32, u32, f64)> = Vec::with_capacity(self.adj.len());
        for i in 0..n {
            for q in self.start[i]..self.start[i + 1] {
                let (a, b) = (class[i], class[self.adj[q] as usize]);
                if a != b {
                    edges.push((a, b, self.w[q]));
                }
            }
        }
        let merged = Csr::from_edges(m, edges);
        let mut small = vec![0.0f32; m * m];
        small.par_chunks_mut(m).enumerate().for_each_init(
            || (vec![0.0f64; m], vec![false; m], RadixHeap::new()),
            |(dist, done, heap), (s, row)| {
                merged.dijkstra(s, dist, done, heap);
                for (o, &d) in row.iter_mut().zip(dist.iter()) {
                    *o = d as f32;
                }
            },
        );
        out.par_chunks_mut(n).enumerate().for_each(|(i, row)| {
            let src = &small[class[i] as usize * m..(class[i] as usize + 1) * m];
            for (o, &c) in row.iter_mut().zip(&class) {
                *o = src[c as usize];
            }
        });
        out
    }

    /// Classes of nodes joined by exact zero-weight edges: (class of each node, numbered in
    /// order of first node; number of classes).
    pub(super) fn zero_classes(&self) -> (Vec<u32>, usize) {
        let n = self.n;
        let mut class = vec![u32::MAX; n];
        let mut m = 0u32;
        let mut stack = Vec::new();
        for s in 0..n {
            if class[s] != u32::MAX {
                continue;
            }
            class[s] = m;
            stack.push(s);
            while let Some(u) = stack.pop() {
                for q in self.start[u]..self.start[u + 1] {
                    let v = self.adj[q] as usize;
                    if self.w[q] == 0.0 && class[v] == u32::MAX {
                        class[v] = m;
                        stack.push(v);
                    }
                }
            }
            m += 1;
        }
        (class, m as usize)
    }

    /// Single-source shortest paths into `dist` (infinite where unreachable), radix heap with
    /// lazy deletion.
    pub(super) fn dijkstra(
        &self,
        s: usize,
        dist: &mut [f64],
        done: &mut [bool],
        heap: &mut RadixHeap,
    ) {
        dist.fill(f64::INFINITY);
        done.fill(false);
        heap.reset();
        dist[s] = 0.0;
        heap.push(0.0, s as u32);
        while let Some((d, u)) = heap.pop() {
            if done[u as usize] || d > dist[u as usize] {
                continue;
            }
            done[u as usize] = true;
            let (a, b) = (self.start[u as usize], self.start[u as usize + 1]);
            for (&v, &w) in self.adj[a..b].iter().zip(&self.w[a..b]) {
                let nd = d + w;
                if nd < dist[v as usize] {
                    dist[v as usize] = nd;
                    heap.push(nd, v);
                }
            }
        }
    }
}

/// Radix heap (monotone priority queue) over the bits of non-negative f64 keys, with lazy
/// deletion: Dijkstra pops keys in non-decreasing order, which is all a radix heap needs.
pub(super) struct RadixHeap {
    pub(super) buckets: Vec<Vec<(u64, u32)>>,
    pub(super) last: u64,
    pub(super) len: usize,
}

impl RadixHeap {
    pub(super) fn new() -> Self {
        RadixHeap {
            buckets: (0..65).map(|_| Vec::new()).collect(),
            last: 0,
            len: 0,
        }
    }

    pub(super) fn reset(&mut self) {
        for b in &mut self.buckets {
            b.clear();
        }
        self.last = 0;
        self.len = 0;
    }

    #[inline]
    pub(super) fn bucket(&self, key: u64) -> usize {
        (64 - (key ^ self.last).leading_zeros()) as usize
    }

    #[inline]
    pub(super) fn push(&mut self, key: f64, v: u32) {
        let k = key.to_bits();
        debug_assert!(k >= self.last);
        let b = self.bucket(k);
        self.buckets[b].push((k, v));
        self.len += 1;
    }

    #[inline]
    pub(super) fn pop(&mut self) -> Option<(f64, u32)> {
        if self.len == 0 {
            return None;
        }
        if self.buckets[0].is_empty() {
            let i = (1..65)
                .find(|&i| !self.buckets[i].is_empty())
                .expect("non-empty");
            let mut moved = std::mem::take(&mut self.buckets[i]);
            self.last = moved.iter().map(|e| e.0).min().expect("non-empty");
            for &e in &moved {
                let b = self.bucket(e.0);
                self.buckets[b].push(e);
            }
            moved.clear();
            self.buckets[i] = moved;
        }
        self.len -= 1;
        self.buckets[0].pop().map(|(k, v)| (f64::from_bits(k), v))
    }
}

/// `G_ij = G_ji = min(G_ij, G_ji)` (the two Dijkstra runs may differ in the last bit), tiled.
pub(super) fn symmetrise_min(g: &mut [f32], n: usize) {
    const T: usize = 64;
    for bi in (0..n).step_by(T) {
        for bj in (bi..n).step_by(T) {
            for i in bi..(bi + T).min(n) {
                for j in bj.max(i + 1)..(bj + T).min(n) {
                    let m = g[i * n + j].min(g[j * n + i]);
                    g[i * n + j] = m;
                    g[j * n + i] = m;
                }
            }
        }
    }
}
