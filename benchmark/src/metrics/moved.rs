//! The "object moved" count of the notebooks: an outcome counts when `‖s − s₀‖ > 1e-3`.

/// Distance above which an outcome counts as a move of the object.
pub const MOVED_EPS: f64 = 1e-3;

/// Whether the engineered outcome `s` differs from the initial state `s0` (Euclidean norm > 1e-3).
pub fn moved(s: &[f64], s0: &[f64]) -> bool {
    let d2: f64 = s.iter().zip(s0).map(|(a, b)| (a - b) * (a - b)).sum();
    d2.sqrt() > MOVED_EPS
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn threshold() {
        assert!(!moved(&[0.6, 0.6], &[0.6, 0.6]));
        assert!(!moved(&[0.6005, 0.6], &[0.6, 0.6]));
        assert!(moved(&[0.602, 0.6], &[0.6, 0.6]));
        assert!(moved(&[0.6, 0.6, -0.9], &[0.6, 0.6, 0.6]));
    }
}
