//! One client connection's activity, for its timeouts: what the socket read, which requests
//! are in flight, and from that the moment the connection may be closed.
//!
//! - A new connection must deliver a complete request head within the header timeout.
//! - Between requests (HTTP/1.1 keep-alive, or an HTTP/2 connection with no stream open) a
//!   connection may stay silent for the idle timeout; once the first byte of a further
//!   HTTP/1.1 request arrives, its head must be complete within the header timeout.
//! - While a request is in flight (its body arriving, its work running or its reply being
//!   written) neither applies: uploads have their own rate bound ([`super::upload`]), work
//!   its time limit, and streamed replies their write timeout ([`super::reply`]).

use std::io;
use std::pin::Pin;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::task::{Context, Poll};
use std::time::Duration;

use axum::body::Body;
use http_body::{Frame, SizeHint};
use tokio::io::{AsyncRead, AsyncWrite, ReadBuf};
use tokio::time::Instant;

/// No time recorded.
const NEVER: u64 = u64::MAX;

/// What a connection is doing, shared by its socket ([`Tracked`]), its requests
/// ([`InFlight`]) and its task.
#[derive(Debug)]
pub struct Activity {
    opened: Instant,
    /// Requests whose reply body has not been dropped yet.
    in_flight: AtomicUsize,
    /// Milliseconds from `opened` to the moment the last request in flight ended.
    idle_since_ms: AtomicU64,
    /// Milliseconds from `opened` to the first byte read while no request was in flight
    /// ([`NEVER`]: none since `idle_since_ms`).
    first_byte_ms: AtomicU64,
    /// Whether a request has been received: until then the header timeout runs from opening.
    served: AtomicBool,
    /// HTTP/2: bytes between requests are control frames, not the start of a head.
    http2: AtomicBool,
}

impl Activity {
    /// A connection opened now.
    pub fn new() -> Arc<Self> {
        Arc::new(Activity {
            opened: Instant::now(),
            in_flight: AtomicUsize::new(0),
            idle_since_ms: AtomicU64::new(0),
            first_byte_ms: AtomicU64::new(NEVER),
            served: AtomicBool::new(false),
            http2: AtomicBool::new(false),
        })
    }

    fn now_ms(&self) -> u64 {
        u64::try_from(self.opened.elapsed().as_millis()).unwrap_or(NEVER - 1)
    }

    fn at(&self, ms: u64) -> Instant {
        // (Saturating: no panic on an absurd offset.)
        self.opened
            .checked_add(Duration::from_millis(ms))
            .unwrap_or(self.opened)
    }

    /// A request arrived: counted in flight until the returned guard (moved into its reply
    /// body) is dropped.
    pub fn begin(self: &Arc<Self>, http2: bool) -> InFlight {
        self.served.store(true, Ordering::Release);
        if http2 {
            self.http2.store(true, Ordering::Release);
        }
        self.in_flight.fetch_add(1, Ordering::AcqRel);
        InFlight(self.clone())
    }

    /// When the connection may be closed for silence: `None` while a request is in flight
    /// (or when the timeout is too long for the clock).
    pub fn deadline(&self, header_timeout: Duration, idle_timeout: Duration) -> Option<Instant> {
        if self.in_flight.load(Ordering::Acquire) > 0 {
            return None;
        }
        let since = self.at(self.idle_since_ms.load(Ordering::Acquire));
        let first_byte = self.first_byte_ms.load(Ordering::Acquire);
        if !self.served.load(Ordering::Acquire) {
            since.checked_add(header_timeout)
        } else if first_byte != NEVER && !self.http2.load(Ordering::Acquire) {
            self.at(first_byte).checked_add(header_timeout)
        } else {
            since.checked_add(idle_timeout)
        }
    }
}

/// One request in flight on a connection ([`Activity::begin`]).
#[derive(Debug)]
pub struct InFlight(Arc<Activity>);

impl Drop for InFlight {
    fn drop(&mut self) {
        let a = &self.0;
        if a.in_flight.fetch_sub(1, Ordering::AcqRel) == 1 {
            a.first_byte_ms.store(NEVER, Ordering::Release);
            a.idle_since_ms.store(a.now_ms(), Ordering::Release);
        }
    }
}

/// A socket that notes, for [`Activity::deadline`], the first byte read between requests.
#[derive(Debug)]
pub struct Tracked<T> {
    inner: T,
    activity: Arc<Activity>,
}

impl<T> Tracked<T> {
    /// `inner` on the connection of `activity`.
    pub fn new(inner: T, activity: Arc<Activity>) -> Self {
        Tracked { inner, activity }
    }
}

/// A reply body holding its [`InFlight`] guard.
pub struct GuardedBody {
    body: Body,
    _in_flight: InFlight,
}

impl GuardedBody {
    /// `body`, counted in flight until it is dropped.
    pub fn new(body: Body, in_flight: InFlight) -> Self {
        GuardedBody {
            body,
            _in_flight: in_flight,
        }
    }
}

impl http_body::Body for GuardedBody {
    type Data = axum::body::Bytes;
    type Error = axum::Error;

    fn poll_frame(
        mut self: Pin<&mut Self>,
        cx: &mut Context<'_>,
    ) -> Poll<Option<Result<Frame<Self::Data>, Self::Error>>> {
        Pin::new(&mut self.body).poll_frame(cx)
    }

    fn is_end_stream(&self) -> bool {
        self.body.is_end_stream()
    }

    fn size_hint(&self) -> SizeHint {
        self.body.size_hint()
    }
}

impl<T: AsyncRead + Unpin> AsyncRead for Tracked<T> {
    fn poll_read(
        mut self: Pin<&mut Self>,
        cx: &mut Context<'_>,
        buf: &mut ReadBuf<'_>,
    ) -> Poll<io::Result<()>> {
        let before = buf.filled().len();
        let polled = Pin::new(&mut self.inner).poll_read(cx, buf);
        if matches!(polled, Poll::Ready(Ok(()))) && buf.filled().len() > before {
            let a = &self.activity;
            if a.in_flight.load(Ordering::Acquire) == 0 {
                let now = a.now_ms();
                let _ = a.first_byte_ms.compare_exchange(
                    NEVER,
                    now,
                    Ordering::AcqRel,
                    Ordering::Acquire,
                );
            }
        }
        polled
    }
}

impl<T: AsyncWrite + Unpin> AsyncWrite for Tracked<T> {
    fn poll_write(
        mut self: Pin<&mut Self>,
        cx: &mut Context<'_>,
        buf: &[u8],
    ) -> Poll<io::Result<usize>> {
        Pin::new(&mut self.inner).poll_write(cx, buf)
    }

    fn poll_flush(mut self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<io::Result<()>> {
        Pin::new(&mut self.inner).poll_flush(cx)
    }

    fn poll_shutdown(mut self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<io::Result<()>> {
        Pin::new(&mut self.inner).poll_shutdown(cx)
    }

    fn poll_write_vectored(
        mut self: Pin<&mut Self>,
        cx: &mut Context<'_>,
        bufs: &[io::IoSlice<'_>],
    ) -> Poll<io::Result<usize>> {
        Pin::new(&mut self.inner).poll_write_vectored(cx, bufs)
    }

    fn is_write_vectored(&self) -> bool {
        self.inner.is_write_vectored()
    }
}
