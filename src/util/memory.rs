//! The process's peak memory, for benchmarks and run reports.

/// Peak resident set size of this process in bytes (`VmHWM` of `/proc/self/status`), or
/// `None` where the system does not say (not Linux).
pub fn peak_rss_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    #[cfg(target_os = "linux")]
    fn peak_rss_grows_with_a_touched_allocation() {
        let before = peak_rss_bytes().unwrap();
        // 64 MiB written page by page must show in the peak (it can only grow).
        let block = vec![1u8; 64 << 20];
        let after = peak_rss_bytes().unwrap();
        assert!(block.iter().step_by(4096).all(|&b| b == 1));
        assert!(after >= before.max(64 << 20), "{before} → {after}");
    }
}
