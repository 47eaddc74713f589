//! Subnormal numbers flushed to zero: a thread pool whose threads run with x86-64's
//! flush-to-zero (FTZ) and denormals-are-zero (DAZ) bits set in `MXCSR`.
//!
//! Why: on Intel CPUs an operation that reads or produces a subnormal `f32` takes a microcode
//! assist of about a hundred cycles. In a trained convolutional VAE, the gradients of the black
//! pixels whose logits are far below zero are subnormal (our reading), and so are the products
//! they reach: on an Intel Xeon, one training iteration of the follow-up's VAE took 6 times
//! longer once it had left the mean-picture plateau, and no longer than before with FTZ and DAZ
//! set (docs/neural.md, "Subnormals").
//!
//! What it computes: every SSE / AVX / AVX-512 operation, scalar or vector, reads a subnormal
//! operand as a zero of its sign (DAZ) and returns a zero of its sign for a result that is
//! subnormal after rounding (FTZ). These are architectural rules of x86-64, the same on every
//! CPU and for every instruction width, so the kernels' paths still agree bit for bit
//! (`kernels/tests/flush.rs`). Other architectures have other flush rules; [`flushing_pool`]
//! refuses to run there rather than compute other bits.
//!
//! Rust and LLVM assume the default floating-point environment, so a constant folded at compile
//! time is computed without the flush. We know of no such constant reaching the subnormal range
//! in the code run in these pools (not proven); the tests compare the flushed kernels across
//! paths and check that the flush took effect.

/// The two `MXCSR` bits: flush-to-zero (15) and denormals-are-zero (6).
#[cfg(target_arch = "x86_64")]
const FTZ_DAZ: u32 = (1 << 15) | (1 << 6);

/// Why a flushing pool cannot be built.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum FlushError {
    #[error(
        "flushing subnormals to zero needs an x86-64 CPU (its MXCSR rules); this is {0}. Train \
         with the flush off (flush_subnormals = false), which computes other bits"
    )]
    Unsupported(&'static str),
    #[error("the flushing thread pool: {0}")]
    Pool(String),
}

#[cfg(target_arch = "x86_64")]
fn read_mxcsr() -> u32 {
    let mut v: u32 = 0;
    // SAFETY: `stmxcsr` stores the 32-bit MXCSR at the given address, which is `v`.
    unsafe {
        std::arch::asm!("stmxcsr [{}]", in(reg) &mut v, options(nostack, preserves_flags));
    }
    v
}

/// Set flush-to-zero and denormals-are-zero on the calling thread.
#[cfg(target_arch = "x86_64")]
fn set_on_this_thread() {
    let v = read_mxcsr() | FTZ_DAZ;
    // SAFETY: `ldmxcsr` loads MXCSR from `v`, which keeps every other bit (rounding mode,
    // exception masks) as it was.
    unsafe {
        std::arch::asm!("ldmxcsr [{}]", in(reg) &v, options(nostack, readonly, preserves_flags));
    }
}

/// Whether the calling thread flushes subnormals (both bits set).
pub fn this_thread_flushes() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        read_mxcsr() & FTZ_DAZ == FTZ_DAZ
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// A pool of `threads` threads (0: as many as the current pool's) that flush subnormals to
/// zero. Run the work with [`rayon::ThreadPool::install`]: the closure and everything it spawns
/// run on the pool's threads, never on the caller's.
pub fn flushing_pool(threads: usize) -> Result<rayon::ThreadPool, FlushError> {
    #[cfg(target_arch = "x86_64")]
    {
        let threads = if threads == 0 {
            rayon::current_num_threads()
        } else {
            threads
        };
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .thread_name(|i| format!("ugl-flush-{i}"))
            .start_handler(|_| set_on_this_thread())
            .build()
            .map_err(|e| FlushError::Pool(e.to_string()))
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        let _ = threads;
        Err(FlushError::Unsupported(std::env::consts::ARCH))
    }
}

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use super::*;
    use std::hint::black_box;

    #[test]
    fn the_pool_flushes_and_the_caller_does_not() {
        let tiny = black_box(1e-30f32);
        let product = |a: f32, b: f32| black_box(a) * black_box(b);
        // Outside: the IEEE default, a subnormal product.
        assert!(!this_thread_flushes());
        assert!(product(tiny, 1e-10).is_subnormal());
        let normal = product(tiny, 2.0).to_bits();
        let pool = flushing_pool(2).unwrap();
        let inside = pool.install(|| {
            (
                this_thread_flushes(),
                product(tiny, 1e-10).to_bits(),
                // DAZ: a subnormal operand reads as zero, so 1 + it is exactly 1 and it times
                // 2^100 is zero.
                product(black_box(f32::from_bits(1)), 2f32.powi(100)).to_bits(),
                // A normal result is untouched.
                product(tiny, 2.0).to_bits(),
            )
        });
        assert_eq!(inside, (true, 0, 0, normal));
        // Every thread of the pool, not only the one that ran the closure.
        let all: Vec<bool> = pool.broadcast(|_| this_thread_flushes());
        assert_eq!(all, vec![true, true]);
        // The caller's environment is untouched.
        assert!(!this_thread_flushes());
        assert!(product(tiny, 1e-10).is_subnormal());
    }
}
