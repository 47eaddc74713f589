//! Matrix products whose bits depend only on their inputs.
//!
//! The contract, on every path: `out[i, j]` is one chain of fused multiply-adds over the inner
//! index in increasing order,
//! `acc = fma(a[i, p], b[p, j], acc)` for `p = 0, 1, ..., k - 1`, starting from `out[i, j]`
//! (`accumulate`) or from `+0`. There is no split of the inner dimension into partial sums, so
//! no reduction tree: blocking the inner dimension only stores the running accumulator in `out`
//! and loads it back, which does not change it. Blocking sizes are constants, not read from the
//! CPU's caches, and the thread count only decides which thread computes which outputs. A
//! vector lane computes exactly what `mul_add` computes, so the scalar, AVX2+FMA and AVX-512
//! paths give the same bits (tested on every path the machine has).
//!
//! `gemm` and `faer` do not promise this: they derive the inner block from the CPU's cache
//! sizes and add the blocks' partial sums, and choose the micro-kernel from the SIMD level.

use std::marker::PhantomData;

use rayon::prelude::*;

use crate::path::{SimdPath, active_path};

/// An element type of the products: `f32` or `f64`.
pub trait Element: Copy + Send + Sync + PartialEq + std::fmt::Debug + 'static {
    const ZERO: Self;
    /// The reference step, `a * b + acc` with one rounding.
    fn fma(a: Self, b: Self, acc: Self) -> Self;
    #[doc(hidden)]
    fn kernels(path: SimdPath) -> KernelSet<Self>;
}

/// A micro-kernel: `MR x NR` outputs at `c` (row stride `ldc`) accumulate the packed panel `ap`
/// (`kc` columns of `MR`) times `kc` rows of `NR` at `bp` (row stride `ldb`), starting from `c`
/// when `load`, else from zero.
#[doc(hidden)]
pub type MicroKernel<T> = unsafe fn(usize, *const T, *const T, usize, *mut T, usize, bool);

#[doc(hidden)]
#[derive(Clone, Copy)]
pub struct KernelSet<T> {
    mr: usize,
    nr: usize,
    /// Inner-dimension block: a `kc x NR` panel of B fills half of a 32 KiB L1 cache.
    kc: usize,
    kernel: MicroKernel<T>,
}

/// Bytes of a packed B micro-panel (`kc x NR`): half a 32 KiB L1 data cache.
const B_PANEL_BYTES: usize = 16 << 10;
/// Row block (a multiple of every path's `MR`: 4, 6, 12); 120 holds a batch of 100 rows.
const MC: usize = 120;
/// Column block (a multiple of every path's `NR`).
const NC: usize = 2048;
/// Below this many multiply-adds a product runs on one thread.
const PARALLEL_WORK: usize = 1 << 18;

/// A `rows x cols` matrix view on a slice, with strides; a transpose swaps the strides.
#[derive(Clone, Copy, Debug)]
pub struct MatRef<'a, T> {
    data: &'a [T],
    rows: usize,
    cols: usize,
    rs: usize,
    cs: usize,
}

impl<'a, T: Element> MatRef<'a, T> {
    /// A row-major `rows x cols` matrix (the first `rows * cols` elements of `data`).
    ///
    /// # Panics
    /// If `data` is shorter than `rows * cols`.
    pub fn row_major(data: &'a [T], rows: usize, cols: usize) -> Self {
        Self::with_strides(data, rows, cols, cols, 1)
    }

    /// A column-major `rows x cols` matrix.
    ///
    /// # Panics
    /// If `data` is shorter than `rows * cols`.
    pub fn col_major(data: &'a [T], rows: usize, cols: usize) -> Self {
        Self::with_strides(data, rows, cols, 1, rows)
    }

    /// Element `(i, j)` at `data[i * rs + j * cs]`.
    ///
    /// # Panics
    /// If the last element lies outside `data`.
    pub fn with_strides(data: &'a [T], rows: usize, cols: usize, rs: usize, cs: usize) -> Self {
        if rows > 0 && cols > 0 {
            let last = (rows - 1) * rs + (cols - 1) * cs;
            assert!(
                last < data.len(),
                "matrix view {rows}x{cols} (strides {rs}, {cs}) outside a slice of {}",
                data.len()
            );
        }
        MatRef {
            data,
            rows,
            cols,
            rs,
            cs,
        }
    }

    /// The transpose (no copy).
    pub fn t(self) -> Self {
        MatRef {
            data: self.data,
            rows: self.cols,
            cols: self.rows,
            rs: self.cs,
            cs: self.rs,
        }
    }

    pub fn rows(&self) -> usize {
        self.rows
    }

    pub fn cols(&self) -> usize {
        self.cols
    }

    /// Element `(i, j)`.
    pub fn at(&self, i: usize, j: usize) -> T {
        self.data[i * self.rs + j * self.cs]
    }
}

/// `out = a b`, or `out += a b` with `accumulate`; `out` is row-major `a.rows() x b.cols()`.
/// Runs on the process's path ([`active_path`]) and the current rayon pool.
///
/// # Panics
/// If the inner dimensions differ or `out` is not `a.rows() * b.cols()` long.
pub fn matmul<T: Element>(out: &mut [T], a: MatRef<'_, T>, b: MatRef<'_, T>, accumulate: bool) {
    matmul_on(active_path(), out, a, b, accumulate)
}

/// [`matmul`] on a given path (the tests compare the paths with it).
///
/// # Panics
/// As [`matmul`], and if the CPU cannot run `path`.
pub fn matmul_on<T: Element>(
    path: SimdPath,
    out: &mut [T],
    a: MatRef<'_, T>,
    b: MatRef<'_, T>,
    accumulate: bool,
) {
    assert_eq!(a.cols, b.rows, "matmul: inner dimensions differ");
    let (m, n, k) = (a.rows, b.cols, a.cols);
    assert_eq!(out.len(), m * n, "matmul: output is not {m}x{n}");
    assert!(
        path.available(),
        "matmul: this CPU cannot run the {path} path"
    );
    if m == 0 || n == 0 {
        return;
    }
    if k == 0 {
        if !accumulate {
            out.fill(T::ZERO);
        }
        return;
    }
    let ks = T::kernels(path);
    let threads = rayon::current_num_threads();
    let c = OutPtr {
        ptr: out.as_mut_ptr(),
        ld: n,
        _life: PhantomData,
    };
    if threads <= 1 || m * n * k < PARALLEL_WORK {
        // SAFETY: the whole of `out` (m x n, row stride n) belongs to this call.
        unsafe { block(&ks, a, b, 0..m, 0..n, c, accumulate) };
        return;
    }
    // Split the longer side of the output into disjoint parts; which thread computes an output
    // never changes how it is computed.
    let parts: Vec<(std::ops::Range<usize>, std::ops::Range<usize>)> = if n >= m {
        split(n, threads, ks.nr).map(|cols| (0..m, cols)).collect()
    } else {
        split(m, threads, ks.mr).map(|rows| (rows, 0..n)).collect()
    };
    parts.into_par_iter().for_each(|(rows, cols)| {
        // SAFETY: the parts are disjoint rectangles of `out`, which outlives the scope.
        unsafe { block(&ks, a, b, rows, cols, c, accumulate) };
    });
}

/// `parts` contiguous ranges covering `0..len`, each a multiple of `align` but the last.
fn split(len: usize, parts: usize, align: usize) -> impl Iterator<Item = std::ops::Range<usize>> {
    let per = len.div_ceil(parts).div_ceil(align) * align;
    (0..len)
        .step_by(per.max(1))
        .map(move |s| s..(s + per).min(len))
}

/// The output pointer, shared by threads that write disjoint parts.
#[derive(Clone, Copy)]
struct OutPtr<'a, T> {
    ptr: *mut T,
    ld: usize,
    _life: PhantomData<&'a mut [T]>,
}
// SAFETY: threads write disjoint elements only (see `matmul_on`).
unsafe impl<T: Send> Send for OutPtr<'_, T> {}
unsafe impl<T: Send> Sync for OutPtr<'_, T> {}

/// The outputs `rows x cols` of `a b`, blocked and packed, on one thread.
///
/// # Safety
/// `c` points to a row-major matrix with row stride `c.ld` that holds `rows x cols`, and no
/// other thread touches those elements.
unsafe fn block<T: Element>(
    ks: &KernelSet<T>,
    a: MatRef<'_, T>,
    b: MatRef<'_, T>,
    rows: std::ops::Range<usize>,
    cols: std::ops::Range<usize>,
    c: OutPtr<'_, T>,
    accumulate: bool,
) {
    let (mr, nr, kc_max) = (ks.mr, ks.nr, ks.kc);
    let k = a.cols;
    let mut bpack = vec![T::ZERO; kc_max * NC.min(cols.len().div_ceil(nr) * nr)];
    let mut apack = vec![T::ZERO; MC.min(rows.len().div_ceil(mr) * mr) * kc_max];
    let mut tile = vec![T::ZERO; mr * nr];
    for jc in cols.clone().step_by(NC) {
        let nc = NC.min(cols.end - jc);
        for pc in (0..k).step_by(kc_max) {
            let kc = kc_max.min(k - pc);
            // Rows of contiguous columns are read in place; other layouts are packed.
            let direct = b.cs == 1;
            if !direct {
                pack_b(&mut bpack, b, pc, kc, jc, nc, nr);
            } else if !nc.is_multiple_of(nr) {
                // Only the last, partial panel is packed (as panel 0).
                let j0 = nc - nc % nr;
                pack_b(&mut bpack, b, pc, kc, jc + j0, nc - j0, nr);
            }
            let load = accumulate || pc > 0;
            for ic in rows.clone().step_by(MC) {
                let mc = MC.min(rows.end - ic);
                pack_a(&mut apack, a, ic, mc, pc, kc, mr);
                for jr in (0..nc).step_by(nr) {
                    let nw = nr.min(nc - jr);
                    let (bp, ldb) = if !direct {
                        (bpack[jr * kc..].as_ptr(), nr)
                    } else if nw == nr {
                        (b.data[pc * b.rs + jc + jr..].as_ptr(), b.rs)
                    } else {
                        (bpack.as_ptr(), nr)
                    };
                    for ir in (0..mc).step_by(mr) {
                        let mw = mr.min(mc - ir);
                        let ap = apack[ir * kc..].as_ptr();
                        // SAFETY: (ic + ir, jc + jr) and the tile's extent lie in this block.
                        let cp = unsafe { c.ptr.add((ic + ir) * c.ld + jc + jr) };
                        if mw == mr && nw == nr {
                            // SAFETY: a full tile inside the block; the panels hold kc x mr
                            // and kc x nr elements.
                            unsafe { (ks.kernel)(kc, ap, bp, ldb, cp, c.ld, load) };
                        } else {
                            // An edge: through a full tile (the padding is zeros and is
                            // dropped).
                            tile.fill(T::ZERO);
                            if load {
                                for i in 0..mw {
                                    for j in 0..nw {
                                        // SAFETY: inside the block.
                                        tile[i * nr + j] = unsafe { *cp.add(i * c.ld + j) };
                                    }
                                }
                            }
                            // SAFETY: `tile` is mr x nr with row stride nr.
                            unsafe { (ks.kernel)(kc, ap, bp, ldb, tile.as_mut_ptr(), nr, true) };
                            for i in 0..mw {
                                for j in 0..nw {
                                    // SAFETY: inside the block.
                                    unsafe { *cp.add(i * c.ld + j) = tile[i * nr + j] };
                                }
                            }
                        }
                    }
                }
            }
        }
    }
}

/// Rows `pc..pc + kc` and columns `jc..jc + nc` of `b`, as panels of `nr` columns: panel `q`
/// holds `kc` rows of `nr` values from `q * nr * kc`, zero-padded.
fn pack_b<T: Element>(
    dst: &mut [T],
    b: MatRef<'_, T>,
    pc: usize,
    kc: usize,
    jc: usize,
    nc: usize,
    nr: usize,
) {
    for (q, j0) in (0..nc).step_by(nr).enumerate() {
        let w = nr.min(nc - j0);
        let panel = &mut dst[q * nr * kc..(q + 1) * nr * kc];
        if b.rs == 1 && b.cs != 1 {
            // A transposed row-major matrix: each panel column is a contiguous run of the
            // source; read it in order and scatter into the (L1-resident) panel.
            for j in 0..w {
                let base = pc + (jc + j0 + j) * b.cs;
                for (p, &v) in b.data[base..base + kc].iter().enumerate() {
                    panel[p * nr + j] = v;
                }
            }
            if w < nr {
                for p in 0..kc {
                    panel[p * nr + w..(p + 1) * nr].fill(T::ZERO);
                }
            }
            continue;
        }
        for p in 0..kc {
            let row = &mut panel[p * nr..(p + 1) * nr];
            let base = (pc + p) * b.rs + (jc + j0) * b.cs;
            if b.cs == 1 {
                row[..w].copy_from_slice(&b.data[base..base + w]);
            } else {
                for (j, v) in row[..w].iter_mut().enumerate() {
                    *v = b.data[base + j * b.cs];
                }
            }
            row[w..].fill(T::ZERO);
        }
    }
}

/// Rows `ic..ic + mc` and columns `pc..pc + kc` of `a`, as panels of `mr` rows: panel `q` holds
/// `kc` columns of `mr` values from `q * mr * kc`, zero-padded. That is [`pack_b`] of the
/// transpose.
fn pack_a<T: Element>(
    dst: &mut [T],
    a: MatRef<'_, T>,
    ic: usize,
    mc: usize,
    pc: usize,
    kc: usize,
    mr: usize,
) {
    pack_b(dst, a.t(), pc, kc, ic, mc, mr);
}

/// The portable micro-kernel (`mul_add`), `MR x NR`.
///
/// # Safety
/// As [`MicroKernel`]: `ap` holds `kc * MR`, `bp` `kc` rows of `NR` (stride `ldb`), and `c` an
/// `MR x NR` tile.
unsafe fn scalar_kernel<T: Element, const MR: usize, const NR: usize>(
    kc: usize,
    ap: *const T,
    bp: *const T,
    ldb: usize,
    c: *mut T,
    ldc: usize,
    load: bool,
) {
    let mut acc = [[T::ZERO; NR]; MR];
    if load {
        for (i, row) in acc.iter_mut().enumerate() {
            for (j, v) in row.iter_mut().enumerate() {
                // SAFETY: inside the tile.
                *v = unsafe { *c.add(i * ldc + j) };
            }
        }
    }
    for p in 0..kc {
        // SAFETY: panel p of both packs.
        let (a, b) = unsafe {
            (
                std::slice::from_raw_parts(ap.add(p * MR), MR),
                std::slice::from_raw_parts(bp.add(p * ldb), NR),
            )
        };
        for (row, &av) in acc.iter_mut().zip(a) {
            for (v, &bv) in row.iter_mut().zip(b) {
                *v = T::fma(av, bv, *v);
            }
        }
    }
    for (i, row) in acc.iter().enumerate() {
        for (j, &v) in row.iter().enumerate() {
            // SAFETY: inside the tile.
            unsafe { *c.add(i * ldc + j) = v };
        }
    }
}

/// An x86 micro-kernel: `MR` rows of `NV` vectors, one FMA chain per lane.
#[cfg(target_arch = "x86_64")]
macro_rules! simd_kernel {
    ($name:ident, $t:ty, $feature:literal, $mr:literal, $nv:literal, $lanes:literal,
     $zero:ident, $load:ident, $store:ident, $set1:ident, $fma:ident) => {
        /// # Safety
        /// As [`MicroKernel`], on a CPU with the target feature.
        #[target_feature(enable = $feature)]
        unsafe fn $name(
            kc: usize,
            ap: *const $t,
            bp: *const $t,
            ldb: usize,
            c: *mut $t,
            ldc: usize,
            load: bool,
        ) {
            use std::arch::x86_64::*;
            let mut acc = [[$zero(); $nv]; $mr];
            if load {
                for i in 0..$mr {
                    for v in 0..$nv {
                        // SAFETY: inside the tile.
                        acc[i][v] = unsafe { $load(c.add(i * ldc + v * $lanes)) };
                    }
                }
            }
            for p in 0..kc {
                let mut b = [$zero(); $nv];
                for v in 0..$nv {
                    // SAFETY: panel p of the B pack.
                    b[v] = unsafe { $load(bp.add(p * ldb + v * $lanes)) };
                }
                for i in 0..$mr {
                    // SAFETY: panel p of the A pack.
                    let a = $set1(unsafe { *ap.add(p * $mr + i) });
                    for v in 0..$nv {
                        acc[i][v] = $fma(a, b[v], acc[i][v]);
                    }
                }
            }
            for i in 0..$mr {
                for v in 0..$nv {
                    // SAFETY: inside the tile.
                    unsafe { $store(c.add(i * ldc + v * $lanes), acc[i][v]) };
                }
            }
        }
    };
}

#[cfg(target_arch = "x86_64")]
simd_kernel!(
    avx2_f32,
    f32,
    "avx2,fma",
    6,
    2,
    8,
    _mm256_setzero_ps,
    _mm256_loadu_ps,
    _mm256_storeu_ps,
    _mm256_set1_ps,
    _mm256_fmadd_ps
);
#[cfg(target_arch = "x86_64")]
simd_kernel!(
    avx512_f32,
    f32,
    "avx512f",
    12,
    2,
    16,
    _mm512_setzero_ps,
    _mm512_loadu_ps,
    _mm512_storeu_ps,
    _mm512_set1_ps,
    _mm512_fmadd_ps
);
#[cfg(target_arch = "x86_64")]
simd_kernel!(
    avx2_f64,
    f64,
    "avx2,fma",
    6,
    2,
    4,
    _mm256_setzero_pd,
    _mm256_loadu_pd,
    _mm256_storeu_pd,
    _mm256_set1_pd,
    _mm256_fmadd_pd
);
#[cfg(target_arch = "x86_64")]
simd_kernel!(
    avx512_f64,
    f64,
    "avx512f",
    6,
    2,
    8,
    _mm512_setzero_pd,
    _mm512_loadu_pd,
    _mm512_storeu_pd,
    _mm512_set1_pd,
    _mm512_fmadd_pd
);

macro_rules! element {
    ($t:ty, $avx2:ident, $avx512:ident, $lanes2:literal, $lanes512:literal, $mr512:literal) => {
        impl Element for $t {
            const ZERO: Self = 0.0;
            #[inline(always)]
            fn fma(a: Self, b: Self, acc: Self) -> Self {
                a.mul_add(b, acc)
            }
            fn kernels(path: SimdPath) -> KernelSet<Self> {
                match path {
                    #[cfg(target_arch = "x86_64")]
                    SimdPath::Avx2 => KernelSet {
                        mr: 6,
                        nr: 2 * $lanes2,
                        kc: B_PANEL_BYTES / (2 * $lanes2 * std::mem::size_of::<$t>()),
                        kernel: $avx2,
                    },
                    #[cfg(target_arch = "x86_64")]
                    SimdPath::Avx512 => KernelSet {
                        mr: $mr512,
                        nr: 2 * $lanes512,
                        kc: B_PANEL_BYTES / (2 * $lanes512 * std::mem::size_of::<$t>()),
                        kernel: $avx512,
                    },
                    _ => KernelSet {
                        mr: 4,
                        nr: 4,
                        kc: B_PANEL_BYTES / (4 * std::mem::size_of::<$t>()),
                        kernel: scalar_kernel::<$t, 4, 4>,
                    },
                }
            }
        }
    };
}

element!(f32, avx2_f32, avx512_f32, 8, 16, 12);
element!(f64, avx2_f64, avx512_f64, 4, 8, 6);

/// The reference: the contract written out, one output at a time.
pub fn matmul_reference<T: Element>(
    out: &mut [T],
    a: MatRef<'_, T>,
    b: MatRef<'_, T>,
    accumulate: bool,
) {
    assert_eq!(a.cols, b.rows, "matmul: inner dimensions differ");
    let (m, n, k) = (a.rows, b.cols, a.cols);
    assert_eq!(out.len(), m * n, "matmul: output is not {m}x{n}");
    for i in 0..m {
        for j in 0..n {
            let mut acc = if accumulate { out[i * n + j] } else { T::ZERO };
            for p in 0..k {
                acc = T::fma(a.at(i, p), b.at(p, j), acc);
            }
            out[i * n + j] = acc;
        }
    }
}
