//! CPU time of this process's live threads, in nanoseconds, from Linux's per-thread scheduler
//! statistics (`/proc/self/task/*/schedstat`): finer than `/proc/self/stat`'s clock ticks
//! (10 ms), fine enough to tell a frame's work from its workers' waiting. Threads that end
//! between two readings take their time with them, so compare readings across work done on
//! threads that live through it (rayon's pool).

/// On-CPU nanoseconds of every live thread of this process, or `None` where the system does
/// not say (not Linux).
pub fn threads_cpu_ns() -> Option<u64> {
    let tasks = std::fs::read_dir("/proc/self/task").ok()?;
    let mut total = 0;
    for task in tasks.flatten() {
        // A thread that ended between the listing and the read counts for nothing.
        if let Ok(text) = std::fs::read_to_string(task.path().join("schedstat")) {
            total += on_cpu_ns(&text)?;
        }
    }
    Some(total)
}

/// The first field of a `schedstat` line: time spent on a CPU, nanoseconds.
fn on_cpu_ns(schedstat: &str) -> Option<u64> {
    schedstat.split_whitespace().next()?.parse().ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_field_of_schedstat_is_the_time_on_a_cpu() {
        assert_eq!(on_cpu_ns("123456789 987 42\n"), Some(123_456_789));
        assert_eq!(on_cpu_ns(""), None);
        assert_eq!(on_cpu_ns("x 1 2"), None);
    }

    #[test]
    fn a_spinning_thread_adds_its_time() {
        let Some(before) = threads_cpu_ns() else {
            return; // not Linux
        };
        // Spin until the threads have used 20 ms more (this one, at least): in nanoseconds,
        // not ticks or microseconds, that takes 20 ms, not 10 s.
        let start = std::time::Instant::now();
        let mut spun = 0;
        while let Some(now) = threads_cpu_ns() {
            spun = now - before;
            if spun >= 20_000_000 || start.elapsed().as_secs() >= 10 {
                break;
            }
        }
        assert!(spun >= 20_000_000, "{spun} ns after 10 s of spinning");
        assert!(start.elapsed().as_secs() < 10);
    }
}
