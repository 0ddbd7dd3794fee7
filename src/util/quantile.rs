//! Quantiles by nearest rank: every percentile seethru reports (metrics' p95, FLIP's p95,
//! the head grid's spread) is one of the values, never an interpolation between two.

/// The nearest-rank `q`-quantile of `sorted` (ascending, not empty; `q` in [0, 1]): its
/// ⌈q n⌉-th smallest value, the smallest for q = 0.
pub fn nearest_rank<T: Copy>(sorted: &[T], q: f64) -> T {
    let n = sorted.len();
    sorted[((q * n as f64).ceil() as usize).clamp(1, n) - 1]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Of 1…20: the p-th percentile is the value p/5 (the rank ⌈p n / 100⌉), p50 the tenth,
    /// p95 the nineteenth; the ends are the smallest and largest.
    #[test]
    fn the_rank_is_the_ceiling_of_q_n() {
        let v: Vec<u32> = (1..=20).collect();
        assert_eq!(nearest_rank(&v, 0.5), 10);
        assert_eq!(nearest_rank(&v, 0.95), 19);
        assert_eq!(nearest_rank(&v, 0.951), 20);
        assert_eq!(nearest_rank(&v, 0.0), 1);
        assert_eq!(nearest_rank(&v, 1.0), 20);
        assert_eq!(nearest_rank(&[7.5f32], 0.95), 7.5);
    }
}
