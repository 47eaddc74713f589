//! Sizes checked before anything is allocated: a configuration whose data cannot fit in this
//! machine's memory, or whose run matrix is absurdly large, is refused with one line naming the
//! key, instead of an allocation failure (an abort with a backtrace) or minutes of silence.

/// At most this many runs in one campaign (the `paper` matrix has 240).
pub const MAX_RUNS: u128 = 1_000_000;

/// Bytes held per exploration epoch, generously: the chosen parameters, the outcome, the
/// latent goal and its encoding, and the neighbour index's share.
pub const BYTES_PER_EPOCH: f64 = 1024.0;

/// The machine's physical memory in bytes (`MemTotal` of `/proc/meminfo`); None where unknown.
pub fn total_memory() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024.0)
}

/// The soft limit of this process's address space (`ulimit -v`, `prlimit --as`, from
/// `/proc/self/limits`); None where unlimited or unknown.
pub fn address_space_limit() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/self/limits").ok()?;
    let line = text.lines().find(|l| l.starts_with("Max address space"))?;
    line["Max address space".len()..]
        .split_whitespace()
        .next()?
        .parse()
        .ok()
}

/// The tightest memory limit of this process's control group and its ancestors (cgroup v2
/// `memory.max`, or v1 `memory.limit_in_bytes`); None where there is none or it is unknown.
pub fn cgroup_memory_limit() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/self/cgroup").ok()?;
    let mut limits = Vec::new();
    for line in text.lines() {
        let mut parts = line.splitn(3, ':');
        let (_, controllers, path) = (parts.next()?, parts.next()?, parts.next()?);
        let (root, file) = match controllers {
            "" => ("/sys/fs/cgroup", "memory.max"),
            c if c.split(',').any(|c| c == "memory") => {
                ("/sys/fs/cgroup/memory", "memory.limit_in_bytes")
            }
            _ => continue,
        };
        let mut dir = std::path::PathBuf::from(format!("{root}{path}"));
        loop {
            if let Ok(v) = std::fs::read_to_string(dir.join(file))
                && let Ok(bytes) = v.trim().parse::<f64>()
            {
                limits.push(bytes);
            }
            if dir.as_os_str().len() <= root.len() || !dir.pop() {
                break;
            }
        }
    }
    limits.into_iter().reduce(f64::min)
}

/// The memory a configuration may plan for, and what sets it: the least of the machine's
/// memory, this process's address-space limit and its control group's memory limit; 1 TiB
/// where none is known.
fn budget() -> (f64, &'static str) {
    [
        (total_memory(), "this machine's memory"),
        (
            address_space_limit(),
            "this process's address-space limit (ulimit -v)",
        ),
        (cgroup_memory_limit(), "this control group's memory limit"),
    ]
    .into_iter()
    .filter_map(|(b, what)| Some((b?, what)))
    .reduce(|a, b| if b.0 < a.0 { b } else { a })
    .unwrap_or((1024.0 * 1024.0 * 1024.0 * 1024.0, "1 TiB"))
}

fn gib(bytes: f64) -> String {
    format!("{:.1} GiB", bytes / (1024.0 * 1024.0 * 1024.0))
}

/// A size refused before anything is allocated: what asks for it, and how much it needs.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum LimitError {
    /// `key = value` needs more memory than this process may use ([`budget`]).
    #[error("{key} = {value} {}", needs_phrase(*needs, *have, what))]
    Memory {
        key: String,
        value: String,
        /// Bytes needed (estimated).
        needs: f64,
        /// Bytes available.
        have: f64,
        /// What sets the budget (`this machine's memory`, ...).
        what: &'static str,
    },
    /// A matrix with more runs than a campaign holds ([`MAX_RUNS`]).
    #[error(
        "the run matrix ({dims}) holds up to {total} runs; a campaign holds at most {MAX_RUNS}"
    )]
    Runs { dims: String, total: u128 },
}

impl LimitError {
    /// The memory error without its `key = value`: `needs about 3.1 GiB of memory, more than ...`.
    pub fn needs(&self) -> String {
        match self {
            LimitError::Memory {
                needs, have, what, ..
            } => needs_phrase(*needs, *have, what),
            other => other.to_string(),
        }
    }
}

fn needs_phrase(needs: f64, have: f64, what: &str) -> String {
    format!(
        "needs about {} of memory, more than {what} ({})",
        gib(needs),
        gib(have)
    )
}

/// Refuse `key = value` if it needs `bytes` (estimated) and that exceeds the memory this
/// process may use ([`budget`]).
pub fn check_fits(key: &str, value: impl std::fmt::Display, bytes: f64) -> Result<(), LimitError> {
    let (have, what) = budget();
    if !bytes.is_finite() || bytes > have {
        return Err(LimitError::Memory {
            key: key.to_string(),
            value: value.to_string(),
            needs: bytes,
            have,
            what,
        });
    }
    Ok(())
}

/// Values of the largest picture among `envs` (70 x 70 = 4900 gray values for the paper's,
/// 64 x 64 x 3 = 12,288 for the follow-up's own ArmBalls); of the whole registry when `envs` is
/// empty.
pub fn image_values(envs: &[crate::env::EnvKind]) -> usize {
    if envs.is_empty() {
        ugl_types::environments()
            .iter()
            .map(|e| e.image.len())
            .max()
            .unwrap_or(0)
    } else {
        envs.iter().map(|e| e.spec().image.len()).max().unwrap_or(0)
    }
}

/// `ugl.images` (the UGL data set: `n` pictures of `values` f32, plus a sparse copy).
pub fn check_images(n: usize, values: usize) -> Result<(), LimitError> {
    check_fits("ugl.images", n, n as f64 * values as f64 * 4.0 * 2.0)
}

/// `ugl embed --grid N` (`N x N` rendered images of f32, held with the `images` training
/// images while they are encoded; the encoders work on an f64 copy of a set). Computed in
/// floating point, so that no size overflows.
pub fn check_grid(grid: usize, images: usize, values: usize) -> Result<(), LimitError> {
    let grid_images = grid as f64 * grid as f64;
    let bytes = (grid_images * (4.0 + 8.0) + images as f64 * 4.0 * 2.0) * values as f64;
    check_fits("--grid", grid, bytes)
}

/// `explore.epochs` (the exploration's per-epoch records).
pub fn check_epochs(n: usize) -> Result<(), LimitError> {
    check_fits("explore.epochs", n, n as f64 * BYTES_PER_EPOCH)
}

/// A network's `hidden` sizes: the weights of the picture-H1-H2 MLP and its mirror, with their
/// gradients and optimiser state (x5), for the registry's largest picture (the network's
/// configuration does not know its environment).
pub fn check_hidden(hidden: [usize; 2]) -> Result<(), LimitError> {
    let [h1, h2] = hidden.map(|h| h as f64);
    let params = 2.0 * (image_values(&[]) as f64 * h1 + h1 * h2) + 200.0 * h2;
    check_fits("hidden", format!("{hidden:?}"), params * 4.0 * 5.0)
}

/// The number of runs of a matrix (the product of its dimensions, without overflow).
pub fn check_runs(dims: &[(&str, usize)]) -> Result<(), LimitError> {
    let total = dims
        .iter()
        .fold(1u128, |acc, (_, n)| acc.saturating_mul(*n as u128));
    if total > MAX_RUNS {
        let what: Vec<String> = dims.iter().map(|(k, n)| format!("{n} {k}")).collect();
        return Err(LimitError::Runs {
            dims: what.join(" x "),
            total,
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn absurd_sizes_are_refused_and_real_ones_pass() {
        assert!(check_images(10_000, 4900).is_ok());
        assert!(check_epochs(5000).is_ok());
        assert!(check_hidden([1200, 1200]).is_ok());
        let e = check_images(100_000_000_000, 4900).unwrap_err().to_string();
        assert!(
            e.starts_with("ugl.images = 100000000000 needs about"),
            "{e}"
        );
        assert!(check_epochs(1 << 63).is_err());
        assert!(check_grid(21, 10_000, 4900).is_ok());
        let e = check_grid(100_000, 300, 4900).unwrap_err().to_string();
        assert!(e.starts_with("--grid = 100000 needs about"), "{e}");
        assert!(check_grid(usize::MAX, 300, 4900).is_err());
        assert!(check_epochs(usize::MAX).is_err());
        assert!(check_hidden([100_000_000, 10]).is_err());
        assert!(check_runs(&[("envs", 2), ("algos", 7), ("reps", 5)]).is_ok());
        let e = check_runs(&[("envs", 2), ("reps", 100_000_000_000)])
            .unwrap_err()
            .to_string();
        assert!(e.contains("at most 1000000"), "{e}");
        assert!(check_runs(&[("a", usize::MAX), ("b", usize::MAX), ("c", usize::MAX)]).is_err());
    }
}
