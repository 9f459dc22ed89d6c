//! Prometheus metrics in the text exposition format 0.0.4, written by hand (a few counters
//! and one histogram do not justify a metrics crate).
//!
//! - `nurbsx_http_requests_total{route,method,status}`: counter;
//! - `nurbsx_http_request_duration_seconds{route}`: histogram;
//! - `nurbsx_http_requests_in_flight`: gauge;
//! - `nurbsx_entities_converted_total`: counter of entities written by `/v1/convert`;
//! - the service's gauges ([`Gauge`]: computing slots, admitted requests, bodies being
//!   received and their bytes, open connections);
//! - `nurbsx_build_info{version}` (always 1) and, on Linux, `process_resident_memory_bytes`,
//!   `process_open_fds` and `process_cpu_seconds_total` read from `/proc/self`.
//!
//! Label values are bounded whatever the clients send: routes are the matched route
//! templates (`unmatched` for the rest), methods the nine of RFC 9110 and PATCH
//! (`other` for the rest), statuses the ones the service answers.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::sync::Mutex;
use std::sync::atomic::{AtomicI64, AtomicU64, Ordering};
use std::time::Duration;

/// Histogram bucket upper bounds, in seconds.
pub const BUCKETS: [f64; 14] = [
    0.001, 0.0025, 0.005, 0.01, 0.025, 0.05, 0.1, 0.25, 0.5, 1.0, 2.5, 5.0, 10.0, 30.0,
];

#[derive(Debug, Default, Clone)]
struct Histogram {
    /// Per bucket (not cumulative; made cumulative when rendered), then the overflow.
    counts: [u64; BUCKETS.len() + 1],
    sum: f64,
}

#[derive(Debug, Default)]
struct Tables {
    requests: BTreeMap<(String, String, u16), u64>,
    latency: BTreeMap<String, Histogram>,
}

/// The service's metrics.
#[derive(Debug, Default)]
pub struct Metrics {
    tables: Mutex<Tables>,
    in_flight: AtomicI64,
    entities_converted: AtomicU64,
}

impl Metrics {
    /// Counts a request start (in-flight gauge).
    pub fn start(&self) {
        self.in_flight.fetch_add(1, Ordering::Relaxed);
    }

    /// Records a finished request (`method` is reduced to [`method_label`]).
    pub fn finish(&self, route: &str, method: &str, status: u16, elapsed: Duration) {
        self.in_flight.fetch_sub(1, Ordering::Relaxed);
        let method = method_label(method);
        let seconds = elapsed.as_secs_f64();
        // A poisoned lock only means another request panicked while counting; the counts
        // are still usable.
        let mut t = self.tables.lock().unwrap_or_else(|p| p.into_inner());
        *t.requests
            .entry((route.to_owned(), method.to_owned(), status))
            .or_insert(0) += 1;
        let h = t.latency.entry(route.to_owned()).or_default();
        let bucket = BUCKETS
            .iter()
            .position(|&b| seconds <= b)
            .unwrap_or(BUCKETS.len());
        if let Some(c) = h.counts.get_mut(bucket) {
            *c += 1;
        }
        h.sum += seconds;
    }

    /// Adds entities written by a conversion.
    pub fn add_entities_converted(&self, n: usize) {
        self.entities_converted
            .fetch_add(u64::try_from(n).unwrap_or(u64::MAX), Ordering::Relaxed);
    }

    /// The text exposition (format 0.0.4), with the service's gauges.
    pub fn render(&self, gauges: &[Gauge]) -> String {
        let t = self.tables.lock().unwrap_or_else(|p| p.into_inner());
        let mut out = String::new();
        // Writing to a String cannot fail; the results are ignored on purpose.
        let _ = writeln!(
            out,
            "# HELP nurbsx_http_requests_total HTTP requests by route, method and status."
        );
        let _ = writeln!(out, "# TYPE nurbsx_http_requests_total counter");
        for ((route, method, status), n) in &t.requests {
            let _ = writeln!(
                out,
                "nurbsx_http_requests_total{{route=\"{}\",method=\"{}\",status=\"{status}\"}} {n}",
                escape(route),
                escape(method)
            );
        }
        let _ = writeln!(
            out,
            "# HELP nurbsx_http_request_duration_seconds HTTP request latency by route."
        );
        let _ = writeln!(out, "# TYPE nurbsx_http_request_duration_seconds histogram");
        for (route, h) in &t.latency {
            let route = escape(route);
            let mut cumulative = 0u64;
            for (bound, n) in BUCKETS.iter().zip(&h.counts) {
                cumulative += n;
                let _ = writeln!(
                    out,
                    "nurbsx_http_request_duration_seconds_bucket{{route=\"{route}\",le=\"{bound}\"}} {cumulative}"
                );
            }
            let total: u64 = h.counts.iter().sum();
            let _ = writeln!(
                out,
                "nurbsx_http_request_duration_seconds_bucket{{route=\"{route}\",le=\"+Inf\"}} {total}"
            );
            let _ = writeln!(
                out,
                "nurbsx_http_request_duration_seconds_sum{{route=\"{route}\"}} {}",
                h.sum
            );
            let _ = writeln!(
                out,
                "nurbsx_http_request_duration_seconds_count{{route=\"{route}\"}} {total}"
            );
        }
        drop(t);
        let own = [
            Gauge::new(
                "nurbsx_http_requests_in_flight",
                "HTTP requests being served.",
                self.in_flight.load(Ordering::Relaxed).max(0).unsigned_abs() as f64,
            ),
            Gauge {
                kind: "counter",
                ..Gauge::new(
                    "nurbsx_entities_converted_total",
                    "Entities written by /v1/convert.",
                    self.entities_converted.load(Ordering::Relaxed) as f64,
                )
            },
        ];
        for g in own.iter().chain(gauges).chain(&process_gauges()) {
            let _ = writeln!(out, "# HELP {} {}", g.name, g.help);
            let _ = writeln!(out, "# TYPE {} {}", g.name, g.kind);
            let _ = writeln!(out, "{} {}", g.name, g.value);
        }
        let _ = writeln!(
            out,
            "# HELP nurbsx_build_info The running version (value always 1)."
        );
        let _ = writeln!(out, "# TYPE nurbsx_build_info gauge");
        let _ = writeln!(
            out,
            "nurbsx_build_info{{version=\"{}\"}} 1",
            escape(env!("CARGO_PKG_VERSION"))
        );
        out
    }
}

/// One sample without labels: a gauge, or a counter with `kind: "counter"`.
#[derive(Debug, Clone)]
pub struct Gauge {
    /// Metric name.
    pub name: &'static str,
    /// `gauge` or `counter`.
    pub kind: &'static str,
    /// The HELP text.
    pub help: &'static str,
    /// The value.
    pub value: f64,
}

impl Gauge {
    /// A gauge.
    pub fn new(name: &'static str, help: &'static str, value: f64) -> Self {
        Gauge {
            name,
            kind: "gauge",
            help,
            value,
        }
    }
}

/// The method label: the methods of RFC 9110 section 9 and PATCH as they are, `other` for
/// anything else (a client can send any token as a method).
pub fn method_label(method: &str) -> &'static str {
    const KNOWN: [&str; 9] = [
        "GET", "HEAD", "POST", "PUT", "DELETE", "CONNECT", "OPTIONS", "TRACE", "PATCH",
    ];
    KNOWN
        .iter()
        .find(|&&m| m == method)
        .copied()
        .unwrap_or("other")
}

/// Resident memory, open descriptors and CPU time of this process, from `/proc/self`
/// (Linux; elsewhere none). CPU time is in clock ticks of 1/100 s, Linux's `USER_HZ`.
fn process_gauges() -> Vec<Gauge> {
    let mut out = Vec::new();
    if let Ok(status) = std::fs::read_to_string("/proc/self/status") {
        let rss_kb = status
            .lines()
            .find_map(|l| l.strip_prefix("VmRSS:"))
            .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<f64>().ok());
        if let Some(kb) = rss_kb {
            out.push(Gauge::new(
                "process_resident_memory_bytes",
                "Resident memory size in bytes.",
                kb * 1024.0,
            ));
        }
    }
    if let Ok(dir) = std::fs::read_dir("/proc/self/fd") {
        out.push(Gauge::new(
            "process_open_fds",
            "Open file descriptors.",
            dir.count() as f64,
        ));
    }
    if let Ok(stat) = std::fs::read_to_string("/proc/self/stat") {
        // Fields after the command name (which may hold spaces, so split after its ')'):
        // state is field 3, utime 14 and stime 15 (proc(5)).
        let ticks: Option<f64> = stat.rsplit_once(')').and_then(|(_, rest)| {
            let f: Vec<&str> = rest.split_whitespace().collect();
            let utime = f.get(11)?.parse::<f64>().ok()?;
            let stime = f.get(12)?.parse::<f64>().ok()?;
            Some(utime + stime)
        });
        if let Some(t) = ticks {
            out.push(Gauge {
                kind: "counter",
                ..Gauge::new(
                    "process_cpu_seconds_total",
                    "User and system CPU time in seconds.",
                    t / 100.0,
                )
            });
        }
    }
    out
}

/// Escapes a label value (backslash, quote, newline), as the exposition format requires.
fn escape(s: &str) -> String {
    s.replace('\\', "\\\\")
        .replace('"', "\\\"")
        .replace('\n', "\\n")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn histogram_buckets_are_cumulative_and_count_matches() {
        let m = Metrics::default();
        for ms in [0, 3, 3, 40, 100_000] {
            m.start();
            m.finish("/r", "GET", 200, Duration::from_millis(ms));
        }
        let text = m.render(&[]);
        // 0 ms and the two 3 ms fall at or below 5 ms; 40 ms below 50 ms; 100 s only +Inf.
        assert!(
            text.contains("_bucket{route=\"/r\",le=\"0.001\"} 1\n"),
            "{text}"
        );
        assert!(
            text.contains("_bucket{route=\"/r\",le=\"0.005\"} 3\n"),
            "{text}"
        );
        assert!(
            text.contains("_bucket{route=\"/r\",le=\"0.05\"} 4\n"),
            "{text}"
        );
        assert!(
            text.contains("_bucket{route=\"/r\",le=\"30\"} 4\n"),
            "{text}"
        );
        assert!(
            text.contains("_bucket{route=\"/r\",le=\"+Inf\"} 5\n"),
            "{text}"
        );
        assert!(text.contains("_count{route=\"/r\"} 5\n"), "{text}");
        assert!(
            text.contains("nurbsx_http_requests_in_flight 0\n"),
            "{text}"
        );
        assert!(text.contains("status=\"200\"} 5\n"), "{text}");
    }

    #[test]
    fn unknown_methods_collapse_to_other() {
        let m = Metrics::default();
        for method in ["GET", "POST", "BREW", "get", "X-ANYTHING"] {
            m.start();
            m.finish("unmatched", method, 405, Duration::ZERO);
        }
        let text = m.render(&[]);
        assert!(
            text.contains("method=\"GET\",status=\"405\"} 1\n"),
            "{text}"
        );
        assert!(
            text.contains("method=\"POST\",status=\"405\"} 1\n"),
            "{text}"
        );
        // `get` is not the method GET (methods are case-sensitive, RFC 9110 9.1).
        assert!(
            text.contains("method=\"other\",status=\"405\"} 3\n"),
            "{text}"
        );
        assert!(text.contains("nurbsx_build_info{version=\""), "{text}");
    }

    #[test]
    fn label_values_are_escaped() {
        assert_eq!(escape("a\"b\\c\nd"), "a\\\"b\\\\c\\nd");
    }
}
