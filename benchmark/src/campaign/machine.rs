//! The machine a run executed on, as recorded in its manifest: host, CPU model and SIMD level.
//!
//! From results version 5 the SIMD level does not change a run's bits: the float kernels
//! ([`ugl_kernels`]) compute the same bits on every path, and the path they ran on is recorded
//! beside the level (`kernels`). The level still says which paths a machine could run, and
//! the optional burn engine's products (`gemm`) still depend on it.

use std::sync::OnceLock;

pub use ugl_types::CpuInfo;

/// The CPU this process runs on (read once).
pub fn cpu_info() -> &'static CpuInfo {
    static CPU: OnceLock<CpuInfo> = OnceLock::new();
    CPU.get_or_init(|| CpuInfo {
        model: cpu_model(),
        simd: simd_level().to_string(),
        kernels: Some(ugl_kernels::active_path().name().to_string()),
    })
}

fn cpu_model() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|text| {
            text.lines()
                .find(|l| l.starts_with("model name") || l.starts_with("Model"))
                .and_then(|l| l.split_once(':'))
                .map(|(_, v)| v.trim().to_string())
        })
        .filter(|s| !s.is_empty())
        .unwrap_or_else(|| "unknown".into())
}

/// The SIMD level of this CPU, named after the x86-64 micro-architecture levels that the
/// kernels' dispatch follows: `x86-64-v4` (AVX-512 F/BW/CD/DQ/VL), `x86-64-v3` (AVX2, FMA),
/// `x86-64-v2` (SSE4.2, POPCNT), `x86-64`; `aarch64-neon` on 64-bit Arm; else the
/// architecture's name.
pub fn simd_level() -> &'static str {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::is_x86_feature_detected as has;
        if has!("avx512f")
            && has!("avx512bw")
            && has!("avx512cd")
            && has!("avx512dq")
            && has!("avx512vl")
        {
            "x86-64-v4"
        } else if has!("avx2") && has!("fma") && has!("bmi1") && has!("bmi2") {
            "x86-64-v3"
        } else if has!("sse4.2") && has!("popcnt") {
            "x86-64-v2"
        } else {
            "x86-64"
        }
    }
    #[cfg(target_arch = "aarch64")]
    {
        "aarch64-neon"
    }
    #[cfg(not(any(target_arch = "x86_64", target_arch = "aarch64")))]
    {
        std::env::consts::ARCH
    }
}

/// The host name (from /etc/hostname or $HOSTNAME).
pub fn host_name() -> &'static str {
    static HOST: OnceLock<String> = OnceLock::new();
    HOST.get_or_init(|| {
        std::fs::read_to_string("/etc/hostname")
            .ok()
            .map(|s| s.trim().to_string())
            .filter(|s| !s.is_empty())
            .or_else(|| std::env::var("HOSTNAME").ok())
            .unwrap_or_else(|| "unknown".into())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cpu_info_is_filled_in() {
        let c = cpu_info();
        assert!(!c.model.is_empty());
        assert!(!c.simd.is_empty());
        #[cfg(target_arch = "x86_64")]
        assert!(c.simd.starts_with("x86-64"), "{}", c.simd);
    }
}
