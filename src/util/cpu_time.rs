//! CPU time of this process, two ways. [`process_cpu_seconds`] (`/proc/self/stat`) counts
//! every thread, ended ones too, in clock ticks (10 ms): for whole commands. [`threads_cpu_ns`]
//! (Linux's per-thread scheduler statistics, `/proc/self/task/*/schedstat`) counts in
//! nanoseconds, fine enough to tell a frame's work from its workers' waiting, but only the
//! live threads: threads that end between two readings take their time with them, so compare
//! its readings across work done on threads that live through it (rayon's pool).

/// CPU seconds (user + system) this process has used, from `/proc/self/stat`; `None` where
/// the system does not say (not Linux). Under load, CPU time is a steadier figure than wall.
pub fn process_cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the command name (which may hold spaces) start at state (field 3);
    // utime and stime are fields 14 and 15, in clock ticks (100 per second on Linux).
    let rest = &stat[stat.rfind(')')? + 2..];
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |i: usize| fields.get(i)?.parse::<f64>().ok();
    Some((ticks(11)? + ticks(12)?) / 100.0)
}

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
    fn the_sum_holds_this_threads_own_time() {
        if threads_cpu_ns().is_none() {
            return; // not Linux
        }
        let own = || {
            let text = std::fs::read_to_string("/proc/thread-self/schedstat").unwrap();
            on_cpu_ns(&text).unwrap()
        };
        // Spin until this thread has run 20 ms more: counted in nanoseconds (not ticks or
        // microseconds) that takes 20 ms, not 10 s.
        let (start, before) = (std::time::Instant::now(), own());
        while own() - before < 20_000_000 && start.elapsed().as_secs() < 10 {}
        let now = own();
        assert!(now - before >= 20_000_000, "{} ns in 10 s", now - before);
        // Every live thread counts, this one with all its time (other tests' threads that
        // end meanwhile take theirs with them, so only a lower bound holds).
        let all = threads_cpu_ns().unwrap();
        assert!(all >= now, "{all} ns for all threads, {now} for this one");
    }
}
