//! Prometheus metrics in the text exposition format 0.0.4, written by hand (a few counters
//! and one histogram do not justify a metrics crate).
//!
//! - `nurbsx_http_requests_total{route,method,status}`: counter;
//! - `nurbsx_http_request_duration_seconds{route}`: histogram;
//! - `nurbsx_http_requests_in_flight`: gauge;
//! - `nurbsx_entities_converted_total`: counter of entities written by `/v1/convert`;
//! - `nurbsx_compute_slots_busy` and `nurbsx_requests_admitted`: gauges of the work gate.
//!
//! Routes are the matched route templates (bounded), never raw paths, so a client cannot
//! grow the label set.

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

    /// Records a finished request.
    pub fn finish(&self, route: &str, method: &str, status: u16, elapsed: Duration) {
        self.in_flight.fetch_sub(1, Ordering::Relaxed);
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

    /// The text exposition (format 0.0.4), with the gate's gauges.
    pub fn render(&self, busy: usize, admitted: usize) -> String {
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
        let gauges = [
            (
                "nurbsx_http_requests_in_flight",
                "gauge",
                "HTTP requests being served.",
                self.in_flight.load(Ordering::Relaxed).max(0).unsigned_abs(),
            ),
            (
                "nurbsx_entities_converted_total",
                "counter",
                "Entities written by /v1/convert.",
                self.entities_converted.load(Ordering::Relaxed),
            ),
            (
                "nurbsx_compute_slots_busy",
                "gauge",
                "Computing slots in use.",
                u64::try_from(busy).unwrap_or(u64::MAX),
            ),
            (
                "nurbsx_requests_admitted",
                "gauge",
                "Requests computing or queued for a slot.",
                u64::try_from(admitted).unwrap_or(u64::MAX),
            ),
        ];
        for (name, kind, help, value) in gauges {
            let _ = writeln!(out, "# HELP {name} {help}");
            let _ = writeln!(out, "# TYPE {name} {kind}");
            let _ = writeln!(out, "{name} {value}");
        }
        out
    }
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
        let text = m.render(0, 0);
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
    fn label_values_are_escaped() {
        assert_eq!(escape("a\"b\\c\nd"), "a\\\"b\\\\c\\nd");
    }
}
