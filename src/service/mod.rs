//! The HTTP service (being written): `nurbsx serve`.

use std::net::SocketAddr;
use std::time::Duration;

use crate::pipeline::Settings;

/// Service configuration; the CLI fills it from flags and environment variables.
#[derive(Debug, Clone)]
pub struct ServeConfig {
    /// Address to listen on (default 127.0.0.1:8080).
    pub addr: SocketAddr,
    /// Largest request body in bytes (default 64 MiB).
    pub max_body_bytes: usize,
    /// Per-request time limit (default 60 s).
    pub request_timeout: Duration,
    /// Most requests doing CPU work at once (default: the number of cores).
    pub max_concurrency: usize,
    /// Pipeline limits and policies.
    pub settings: Settings,
}

impl Default for ServeConfig {
    fn default() -> Self {
        ServeConfig {
            addr: SocketAddr::from(([127, 0, 0, 1], 8080)),
            max_body_bytes: 64 << 20,
            request_timeout: Duration::from_secs(60),
            max_concurrency: std::thread::available_parallelism().map_or(2, |n| n.get()),
            settings: Settings::default(),
        }
    }
}

/// Runs the service until SIGTERM or Ctrl-C.
pub fn serve(config: ServeConfig) -> std::io::Result<()> {
    let _ = config;
    Err(std::io::Error::other("the HTTP service is being written"))
}
