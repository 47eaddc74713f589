//! KL-coverage (paper Section 4.2; docs/original-code.md section 4): the one implementation,
//! used by the explorer's curves, the discovery measures and the environment registry's check.
//!
//! The engineered outcomes are binned with `bins` bins per coordinate over [-1,1] (30 in every
//! registered environment; numpy `histogramdd` semantics: edges `linspace(-1, 1, bins + 1)`, bins
//! closed on the left, the last bin also closed on the right). The achievable set is the set of
//! (x, y) bins that intersect the open unit disk (756 of the 900), computed exactly in integer
//! arithmetic, times every bin of the further coordinates (ArmArrow's angle: 22,680 cells).
//! KLC = KL(visited ‖ uniform on achievable) = ln(N_achievable) − H(visited), +inf when an outcome
//! lies outside the achievable set.

use thiserror::Error;

/// Bins per coordinate of the registered environments' grids (the paper's 30).
pub const BINS: usize = 30;

/// Errors of the KL-coverage computation.
#[derive(Debug, Clone, Error, PartialEq)]
pub enum KlcError {
    /// A point has the wrong number of coordinates.
    #[error("outcome has {got} coordinates, expected {expected}")]
    Dimension { got: usize, expected: usize },
    /// A coordinate is NaN.
    #[error("outcome coordinate is NaN")]
    NaN,
    /// No outcomes at all: the visited distribution is undefined.
    #[error("no outcomes: KL-coverage is undefined for an empty set")]
    Empty,
    /// A grid whose first two coordinates cannot be a position in the disk, or too large.
    #[error(
        "a KL-coverage grid of {dims} coordinates and {bins} bins per coordinate is not a disk grid (2 or more coordinates, an even number of bins, at most 2^26 cells)"
    )]
    Grid { dims: usize, bins: usize },
}

/// The KL-coverage measure on a grid of `bins` per coordinate over [-1, 1]^dim.
#[derive(Clone, Debug)]
pub struct KlCoverage {
    dim: usize,
    bins: usize,
    edges: Vec<f64>,
    achievable: Vec<bool>,
    n_achievable: usize,
}

/// Whether the square bin (ix, iy) of the `bins` x `bins` grid over [-1,1]^2 intersects the open
/// unit disk. Edges are k/(bins/2) - 1, so in units of 2/bins the test is exact in integers.
pub fn bin_in_open_disk(ix: usize, iy: usize, bins: usize) -> bool {
    let half = (bins / 2) as i64;
    // Bin i spans [i - half, i - half + 1] in units of 2/bins; distance of the interval to 0:
    let near = |i: usize| -> i64 {
        let (lo, hi) = (i as i64 - half, i as i64 - half + 1);
        if lo <= 0 && 0 <= hi {
            0
        } else {
            lo.abs().min(hi.abs())
        }
    };
    let (dx, dy) = (near(ix), near(iy));
    dx * dx + dy * dy < half * half
}

impl KlCoverage {
    /// The paper's measure for outcomes of dimension `dim` (2: ArmBall, 3: ArmArrow): [`BINS`]
    /// bins per coordinate, the first two a position in the disk.
    pub fn new(dim: usize) -> Result<Self, KlcError> {
        if !(2..=3).contains(&dim) {
            return Err(KlcError::Grid {
                dims: dim,
                bins: BINS,
            });
        }
        Self::disk(dim, BINS)
    }

    /// The grid of `bins` per coordinate over [-1, 1]^dim whose first two coordinates are a
    /// position in the unit disk.
    pub fn disk(dim: usize, bins: usize) -> Result<Self, KlcError> {
        let bad = KlcError::Grid { dims: dim, bins };
        if dim < 2 || bins < 2 || !bins.is_multiple_of(2) {
            return Err(bad);
        }
        let n_cells = bins
            .checked_pow(dim as u32)
            .filter(|&n| n <= 1 << 26)
            .ok_or(bad)?;
        // np.linspace(-1, 1, bins + 1): start + i * step, last edge exactly 1.
        let step = 2.0 / bins as f64;
        let mut edges: Vec<f64> = (0..=bins).map(|i| i as f64 * step + -1.0).collect();
        edges[bins] = 1.0;
        let per_pair = n_cells / (bins * bins);
        let mut achievable = Vec::with_capacity(n_cells);
        for ix in 0..bins {
            for iy in 0..bins {
                let ok = bin_in_open_disk(ix, iy, bins);
                achievable.extend(std::iter::repeat_n(ok, per_pair));
            }
        }
        let n_achievable = achievable.iter().filter(|&&a| a).count();
        Ok(KlCoverage {
            dim,
            bins,
            edges,
            achievable,
            n_achievable,
        })
    }

    /// The measure over the whole square [-1, 1]², every one of the 900 cells achievable: for
    /// an object whose reachable set is not the arm's disk (ArmBalls' distractor walks in
    /// [-0.95, 0.95]², which meets every cell).
    pub fn whole_square() -> Self {
        let mut k = KlCoverage::new(2).expect("2 is a supported dimension");
        k.achievable.fill(true);
        k.n_achievable = k.achievable.len();
        k
    }

    /// Outcome dimension.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// Bins per coordinate.
    pub fn bins(&self) -> usize {
        self.bins
    }

    /// Number of achievable cells (756 for ArmBall, 22,680 for ArmArrow).
    pub fn n_achievable(&self) -> usize {
        self.n_achievable
    }

    /// Total number of cells (bins^dim).
    pub fn n_cells(&self) -> usize {
        self.achievable.len()
    }

    /// The largest possible KLC: every outcome in one cell, ln(N_achievable).
    pub fn max_klc(&self) -> f64 {
        libm::log(self.n_achievable as f64)
    }

    /// Bin of one coordinate, numpy histogramdd semantics; None outside [-1, 1].
    #[inline]
    pub fn bin(&self, v: f64) -> Option<usize> {
        if !(-1.0..=1.0).contains(&v) {
            return None;
        }
        if v == 1.0 {
            return Some(self.bins - 1);
        }
        // searchsorted(edges, v, side='right') - 1
        let k = self.edges.partition_point(|&e| e <= v);
        Some(k - 1)
    }

    /// Cell index (C order over the dimensions) of a point; None when outside [-1,1]^dim.
    pub fn cell(&self, p: &[f64]) -> Result<Option<usize>, KlcError> {
        if p.len() != self.dim {
            return Err(KlcError::Dimension {
                got: p.len(),
                expected: self.dim,
            });
        }
        let mut idx = 0;
        for &v in p {
            if v.is_nan() {
                return Err(KlcError::NaN);
            }
            match self.bin(v) {
                Some(b) => idx = idx * self.bins + b,
                None => return Ok(None),
            }
        }
        Ok(Some(idx))
    }

    /// Whether a cell is achievable.
    pub fn is_achievable(&self, cell: usize) -> bool {
        self.achievable[cell]
    }

    /// An empty incremental histogram for this measure.
    pub fn histogram(&self) -> CoverageHistogram<'_> {
        CoverageHistogram {
            klc: self,
            counts: vec![0; self.achievable.len()],
            touched: Vec::new(),
            total: 0,
            outside: 0,
            reached_achievable: 0,
        }
    }

    /// KL-coverage of a set of points (each of length `dim`).
    pub fn evaluate<'p, I: IntoIterator<Item = &'p [f64]>>(
        &self,
        points: I,
    ) -> Result<f64, KlcError> {
        let mut h = self.histogram();
        for p in points {
            h.add(p)?;
        }
        h.klc()
    }
}

/// An incremental histogram of outcomes: add points one at a time, read KLC and coverage at any
/// moment in O(number of visited cells).
#[derive(Clone, Debug)]
pub struct CoverageHistogram<'a> {
    klc: &'a KlCoverage,
    counts: Vec<u32>,
    touched: Vec<usize>,
    total: u64,
    outside: u64,
    reached_achievable: usize,
}

impl CoverageHistogram<'_> {
    /// Add one outcome.
    pub fn add(&mut self, p: &[f64]) -> Result<(), KlcError> {
        self.total += 1;
        match self.klc.cell(p)? {
            None => self.outside += 1,
            Some(c) => {
                if !self.klc.achievable[c] {
                    self.outside += 1;
                }
                if self.counts[c] == 0 {
                    self.touched.push(c);
                    if self.klc.achievable[c] {
                        self.reached_achievable += 1;
                    }
                }
                self.counts[c] += 1;
            }
        }
        Ok(())
    }

    /// Number of outcomes added.
    pub fn total(&self) -> u64 {
        self.total
    }

    /// KL(visited ‖ uniform on achievable) = Σ p ln(p / q), q = 1/N_achievable; +inf if any
    /// outcome is outside the achievable set.
    pub fn klc(&self) -> Result<f64, KlcError> {
        if self.total == 0 {
            return Err(KlcError::Empty);
        }
        if self.outside > 0 {
            return Ok(f64::INFINITY);
        }
        let n = self.total as f64;
        let q = 1.0 / self.klc.n_achievable as f64;
        let mut cells = self.touched.clone();
        cells.sort_unstable();
        let mut s = 0.0;
        for c in cells {
            let p = self.counts[c] as f64 / n;
            s += p * libm::log(p / q);
        }
        Ok(s)
    }

    /// Fraction of the achievable cells that hold at least one outcome.
    pub fn coverage(&self) -> f64 {
        self.reached_achievable as f64 / self.klc.n_achievable as f64
    }

    /// Number of distinct cells visited (achievable or not).
    pub fn n_visited(&self) -> usize {
        self.touched.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_whole_square_counts_every_cell() {
        let k = KlCoverage::whole_square();
        assert_eq!((k.n_achievable(), k.n_cells()), (900, 900));
        // A corner outcome is outside the disk's cells, inside the square's.
        let corner: &[f64] = &[0.95, -0.95];
        assert_eq!(
            KlCoverage::new(2).unwrap().evaluate([corner]).unwrap(),
            f64::INFINITY
        );
        assert!((k.evaluate([corner]).unwrap() - (900f64).ln()).abs() < 1e-12);
    }

    #[test]
    fn achievable_counts() {
        let b = KlCoverage::new(2).unwrap();
        assert_eq!(b.n_achievable(), 756);
        assert_eq!(b.n_cells(), 900);
        let a = KlCoverage::new(3).unwrap();
        assert_eq!(a.n_achievable(), 22_680);
        assert!((b.max_klc() - 6.628041).abs() < 1e-6);
        assert!((a.max_klc() - 10.029239).abs() < 1e-6);
        assert!(KlCoverage::new(4).is_err());
    }

    #[test]
    fn achievable_matches_monte_carlo_definition() {
        // Every bin holding a point of the open disk is achievable, and a fine grid of points in
        // the disk reaches every achievable bin.
        let b = KlCoverage::new(2).unwrap();
        let mut hit = vec![false; 900];
        let n = 1200;
        for i in 0..n {
            for j in 0..n {
                let x = -1.0 + (i as f64 + 0.5) * 2.0 / n as f64;
                let y = -1.0 + (j as f64 + 0.5) * 2.0 / n as f64;
                if x * x + y * y < 1.0 {
                    let c = b.cell(&[x, y]).unwrap().unwrap();
                    assert!(b.is_achievable(c));
                    hit[c] = true;
                }
            }
        }
        assert_eq!(hit.iter().filter(|&&h| h).count(), 756);
    }

    #[test]
    fn one_bin_gives_the_maximum() {
        let b = KlCoverage::new(2).unwrap();
        let pts = vec![[0.6, 0.6]; 100];
        let v = b.evaluate(pts.iter().map(|p| &p[..])).unwrap();
        assert!((v - 756f64.ln()).abs() < 1e-12);
        let a = KlCoverage::new(3).unwrap();
        let v = a.evaluate([&[0.6, 0.6, 0.6][..]]).unwrap();
        assert!((v - 22_680f64.ln()).abs() < 1e-12);
    }

    #[test]
    fn uniform_over_achievable_is_zero() {
        let b = KlCoverage::new(2).unwrap();
        let mut h = b.histogram();
        // One point at the centre-most part of each achievable bin.
        for ix in 0..BINS {
            for iy in 0..BINS {
                if bin_in_open_disk(ix, iy, BINS) {
                    let lo = |i: usize| (i as f64 - 15.0) / 15.0;
                    // The corner nearest the origin, nudged inside the bin and inside the disk.
                    let px = if ix < 15 {
                        lo(ix + 1) - 1e-9
                    } else {
                        lo(ix) + 1e-9
                    };
                    let py = if iy < 15 {
                        lo(iy + 1) - 1e-9
                    } else {
                        lo(iy) + 1e-9
                    };
                    h.add(&[px, py]).unwrap();
                }
            }
        }
        assert!(h.klc().unwrap().abs() < 1e-12);
        assert_eq!(h.coverage(), 1.0);
    }

    #[test]
    fn outside_is_infinite_never_a_panic() {
        let b = KlCoverage::new(2).unwrap();
        // Inside [-1,1]^2 but in a corner bin, outside the disk.
        assert_eq!(
            b.evaluate([&[0.99, 0.99][..], &[0.0, 0.0][..]]).unwrap(),
            f64::INFINITY
        );
        // Outside the histogram range.
        assert_eq!(b.evaluate([&[1.5, 0.0][..]]).unwrap(), f64::INFINITY);
        assert_eq!(
            b.evaluate([&[f64::INFINITY, 0.0][..]]).unwrap(),
            f64::INFINITY
        );
        assert_eq!(b.evaluate([&[f64::NAN, 0.0][..]]), Err(KlcError::NaN));
        assert_eq!(
            b.evaluate([&[0.0][..]]),
            Err(KlcError::Dimension {
                got: 1,
                expected: 2
            })
        );
        assert_eq!(b.evaluate(std::iter::empty()), Err(KlcError::Empty));
    }

    #[test]
    fn numpy_bin_edges() {
        let b = KlCoverage::new(2).unwrap();
        assert_eq!(b.bin(-1.0), Some(0));
        assert_eq!(b.bin(1.0), Some(29));
        assert_eq!(b.bin(0.0), Some(15));
        assert_eq!(b.bin(-1e-300), Some(14));
        assert_eq!(b.bin(1.0 + 1e-12), None);
        assert_eq!(b.bin(-1.0 - 1e-12), None);
        for i in 0..=30 {
            let e = i as f64 * (2.0 / 30.0) - 1.0;
            assert_eq!(b.bin(e.min(1.0)), Some(i.min(29)));
        }
    }

    #[test]
    fn klc_is_ln_n_minus_entropy() {
        let b = KlCoverage::new(2).unwrap();
        // 3 points in bin A, 1 in bin B.
        let pts = [[0.01, 0.01], [0.02, 0.02], [0.03, 0.03], [-0.5, 0.2]];
        let v = b.evaluate(pts.iter().map(|p| &p[..])).unwrap();
        let h = -(0.75f64 * 0.75f64.ln() + 0.25 * 0.25f64.ln());
        assert!((v - (756f64.ln() - h)).abs() < 1e-12);
    }
}
