//! The machine a report was measured on, which every figure names.

/// CPU model, threads and load when the report started.
pub struct Machine {
    pub cpu: String,
    /// Threads the renders and Embree use (all the cores the process may run on).
    pub threads: usize,
    /// The 1-minute load average at the start: other work on the machine skews timings.
    pub load: String,
}

impl Machine {
    pub fn this() -> Machine {
        let cpu = std::fs::read_to_string("/proc/cpuinfo")
            .ok()
            .and_then(|s| {
                s.lines()
                    .find(|l| l.starts_with("model name"))
                    .and_then(|l| l.split_once(':'))
                    .map(|(_, v)| v.trim().to_owned())
            })
            .unwrap_or_else(|| "unknown CPU".into());
        let load = std::fs::read_to_string("/proc/loadavg")
            .ok()
            .and_then(|s| s.split_whitespace().next().map(str::to_owned))
            .unwrap_or_else(|| "unknown".into());
        Machine {
            cpu,
            threads: std::thread::available_parallelism().map_or(1, |n| n.get()),
            load,
        }
    }

    /// One line for the report's head.
    pub fn describe(&self) -> String {
        format!(
            "{}, {} threads, load average {} at the start",
            self.cpu, self.threads, self.load
        )
    }

    /// What a figure's caption says about where and how it was measured.
    pub fn caption(&self, threads: usize, extra: &str) -> String {
        let mut s = format!("{}, {} thread{}", self.cpu, threads, plural(threads));
        if !extra.is_empty() {
            s += ", ";
            s += extra;
        }
        s
    }
}

fn plural(n: usize) -> &'static str {
    if n == 1 { "" } else { "s" }
}
