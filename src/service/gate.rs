//! Bounded CPU work: admission, a queue, and `spawn_blocking`.
//!
//! Policy (documented in README "HTTP service"):
//! - at most `max_concurrency` requests compute at once (a semaphore of that many permits);
//! - a request is admitted once its body has arrived ([`super::upload`] bounds the bodies
//!   still arriving) and waits for a permit at most [`QUEUE_WAIT`]; it is refused at once
//!   with 503 `overloaded` when
//!   - [`QUEUE_FACTOR`] × `max_concurrency` requests already wait (besides those
//!     computing), or
//!   - the bodies of the admitted requests would pass the gate's byte budget (the service
//!     sets 5 × `max_concurrency` × `max_body_bytes`), or
//!   - at the measured pace the requests ahead would keep it waiting longer than
//!     [`QUEUE_WAIT`] (waiting ahead × mean computing time / slots);
//! - a request that waited [`QUEUE_WAIT`] without a permit gets 503 `overloaded` too; every
//!   refusal carries `Retry-After` the time the queue takes to drain at the measured pace
//!   ([`Gate::retry_after_s`], 1 to [`MAX_RETRY_AFTER_S`] seconds);
//! - the permit moves into the blocking task with the request's stop signal
//!   ([`crate::pipeline::Cancel`]): when the request's future is dropped (time limit,
//!   connection closed) or [`Gate::stop_all`] is called, the computation stops at its next
//!   poll and frees its slot; the count of busy slots never lies;
//! - a streamed reply ([`Gate::stream`]) keeps its slot until its last chunk is taken by
//!   the client; its stop signal fires when the client is gone, when the request's time
//!   limit passes (also while streaming) or when the client leaves a chunk untaken for the
//!   write timeout.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::time::Duration;

use tokio::sync::Semaphore;

use super::error::ApiError;
use super::reply::{self, ReplyWriter};
use crate::pipeline::Cancel;

/// How many requests may wait per computing slot: enough for 32 keep-alive clients on 2
/// slots (measured, README "HTTP service"); the byte budget and the predicted wait bound
/// what a long queue may cost.
pub const QUEUE_FACTOR: usize = 16;

/// The longest a request waits for a computing slot before 503.
pub const QUEUE_WAIT: Duration = Duration::from_secs(2);

/// The longest `Retry-After` the gate advises, in seconds.
pub const MAX_RETRY_AFTER_S: u64 = 60;

/// The admission counter and the computing-slot semaphore.
#[derive(Debug)]
pub struct Gate {
    permits: Arc<Semaphore>,
    slots: usize,
    admitted: AtomicUsize,
    max_admitted: usize,
    admitted_bytes: AtomicUsize,
    max_admitted_bytes: usize,
    shutting_down: AtomicBool,
    stop_all: Arc<AtomicBool>,
    /// Mean computing time of the recent requests, in microseconds (exponentially weighted,
    /// 1/8 per request; 0 until the first one ends).
    mean_work_us: Arc<AtomicU64>,
}

/// Sets a request's stop flag when the request's future goes away.
struct StopOnDrop(Arc<AtomicBool>);

impl Drop for StopOnDrop {
    fn drop(&mut self) {
        self.0.store(true, Ordering::Release);
    }
}

/// Holds one admission; dropping it frees the place and the body's bytes.
#[derive(Debug)]
pub struct Admission<'g> {
    gate: &'g Gate,
    bytes: usize,
}

impl Drop for Admission<'_> {
    fn drop(&mut self) {
        self.gate.admitted.fetch_sub(1, Ordering::AcqRel);
        self.gate
            .admitted_bytes
            .fetch_sub(self.bytes, Ordering::AcqRel);
    }
}

impl Gate {
    /// A gate with `slots` computing slots (0 refuses all work: useful in tests) and no byte
    /// budget.
    pub fn new(slots: usize) -> Self {
        Gate::with_byte_budget(slots, usize::MAX)
    }

    /// A gate whose admitted requests' bodies hold at most `max_bytes` together.
    pub fn with_byte_budget(slots: usize, max_bytes: usize) -> Self {
        Gate {
            permits: Arc::new(Semaphore::new(slots.min(Semaphore::MAX_PERMITS))),
            slots,
            admitted: AtomicUsize::new(0),
            max_admitted: slots.saturating_mul(1 + QUEUE_FACTOR),
            admitted_bytes: AtomicUsize::new(0),
            max_admitted_bytes: max_bytes,
            shutting_down: AtomicBool::new(false),
            stop_all: Arc::new(AtomicBool::new(false)),
            mean_work_us: Arc::new(AtomicU64::new(0)),
        }
    }

    /// Seconds for the admitted requests to drain at the measured pace: admitted × mean
    /// computing time / slots, rounded up, from 1 to [`MAX_RETRY_AFTER_S`].
    pub fn retry_after_s(&self) -> u64 {
        let mean_us = self.mean_work_us.load(Ordering::Relaxed);
        let admitted = u64::try_from(self.admitted()).unwrap_or(u64::MAX);
        let slots = u64::try_from(self.slots.max(1)).unwrap_or(1);
        admitted
            .saturating_mul(mean_us)
            .div_ceil(slots.saturating_mul(1_000_000))
            .clamp(1, MAX_RETRY_AFTER_S)
    }

    /// An `overloaded` refusal with the drain-time `Retry-After`.
    fn overloaded(&self, message: String) -> ApiError {
        ApiError {
            retry_after_s: self.retry_after_s(),
            ..ApiError::overloaded(message)
        }
    }

    /// Stops every computation at its next poll (the end of a shutdown's drain).
    pub fn stop_all(&self) {
        self.stop_all.store(true, Ordering::Release);
    }

    /// Admits a request whose body holds `body_bytes`, or refuses it with 503 (see the
    /// module notes).
    pub fn admit(&self, body_bytes: usize) -> Result<Admission<'_>, ApiError> {
        let ahead = self.admitted.fetch_add(1, Ordering::AcqRel);
        let held = self.admitted_bytes.fetch_add(body_bytes, Ordering::AcqRel);
        let admission = Admission {
            gate: self,
            bytes: body_bytes,
        };
        let refusal = if ahead >= self.max_admitted {
            Some(format!(
                "all {} computing slots and {} queue places are taken; retry shortly",
                self.slots,
                self.max_admitted.saturating_sub(self.slots)
            ))
        } else if held.saturating_add(body_bytes) > self.max_admitted_bytes {
            Some(format!(
                "the admitted requests' bodies would pass the server's {} bytes; retry shortly",
                self.max_admitted_bytes
            ))
        } else {
            let waiting = ahead.saturating_sub(self.slots.saturating_sub(1));
            let wait_us = u64::try_from(waiting)
                .unwrap_or(u64::MAX)
                .saturating_mul(self.mean_work_us.load(Ordering::Relaxed))
                / u64::try_from(self.slots.max(1)).unwrap_or(1);
            (wait_us > u64::try_from(QUEUE_WAIT.as_micros()).unwrap_or(u64::MAX)).then(|| {
                format!(
                    "{waiting} requests wait ahead, about {} ms at the measured pace, more \
                     than the {} ms a request may wait; retry shortly",
                    wait_us / 1000,
                    QUEUE_WAIT.as_millis()
                )
            })
        };
        if let Some(message) = refusal {
            drop(admission);
            return Err(self.overloaded(message));
        }
        Ok(admission)
    }

    /// Whether a new request would be admitted and the server is not shutting down.
    pub fn ready(&self) -> bool {
        !self.shutting_down.load(Ordering::Acquire)
            && self.admitted.load(Ordering::Acquire) < self.max_admitted
    }

    /// Marks the server as shutting down (`/readyz` then answers 503).
    pub fn begin_shutdown(&self) {
        self.shutting_down.store(true, Ordering::Release);
    }

    /// Whether shutdown has begun.
    pub fn shutting_down(&self) -> bool {
        self.shutting_down.load(Ordering::Acquire)
    }

    /// Requests admitted now (computing or queued).
    pub fn admitted(&self) -> usize {
        self.admitted.load(Ordering::Acquire)
    }

    /// Computing slots in use now.
    pub fn busy(&self) -> usize {
        self.slots
            .saturating_sub(self.permits.available_permits().min(self.slots))
    }

    /// A computing slot, waiting at most [`QUEUE_WAIT`].
    async fn slot(&self) -> Result<tokio::sync::OwnedSemaphorePermit, ApiError> {
        match tokio::time::timeout(QUEUE_WAIT, self.permits.clone().acquire_owned()).await {
            Ok(Ok(permit)) => Ok(permit),
            Ok(Err(_closed)) => Err(ApiError::overloaded("the server is shutting down")),
            Err(_elapsed) => Err(self.overloaded(format!(
                "all {} computing slots stayed busy for {} ms; retry shortly",
                self.slots,
                QUEUE_WAIT.as_millis()
            ))),
        }
    }

    /// Runs `work`, adding its duration to the measured pace.
    fn timed<T>(mean: &AtomicU64, work: impl FnOnce() -> T) -> T {
        let start = std::time::Instant::now();
        let result = work();
        let took = u64::try_from(start.elapsed().as_micros()).unwrap_or(u64::MAX);
        // A lost update between two requests ending together only delays the average.
        let old = mean.load(Ordering::Relaxed);
        let new = if old == 0 {
            took
        } else {
            old - old / 8 + took / 8
        };
        mean.store(new.max(1), Ordering::Relaxed);
        result
    }

    /// Runs CPU-bound `work` on the blocking pool once a slot is free (waiting at most
    /// [`QUEUE_WAIT`]), giving it the request's stop signal to poll. A panic in `work`
    /// becomes a logged 500 with a generic message.
    pub async fn run<T, F>(&self, work: F) -> Result<T, ApiError>
    where
        F: FnOnce(Cancel) -> Result<T, ApiError> + Send + 'static,
        T: Send + 'static,
    {
        let permit = self.slot().await?;
        let span = tracing::Span::current();
        let stop = Arc::new(AtomicBool::new(false));
        let _stop_on_drop = StopOnDrop(stop.clone());
        let all = self.stop_all.clone();
        let cancel =
            Cancel::new(move || stop.load(Ordering::Acquire) || all.load(Ordering::Acquire));
        let mean = self.mean_work_us.clone();
        let handle = tokio::task::spawn_blocking(move || {
            let _permit = permit;
            let _entered = span.enter();
            Self::timed(&mean, || work(cancel))
        });
        match handle.await {
            Ok(result) => result,
            Err(e) if e.is_panic() => {
                panicked(e.into_panic().as_ref());
                Err(ApiError::internal())
            }
            Err(e) => {
                tracing::error!(error = %e, "request computation was cancelled");
                Err(ApiError::internal())
            }
        }
    }

    /// Runs `work` as [`Gate::run`] does, but `work` writes its reply into a
    /// [`ReplyWriter`] that streams it ([`super::reply`]); returns the reply's head (set
    /// with [`ReplyWriter::head`]) and body once the first chunk is ready, or the error
    /// `work` met before that. The slot stays taken until the reply is written; the stop
    /// signal fires when the client is gone (the time limit dropping the request counts),
    /// at `deadline` once the reply streams, or at [`Gate::stop_all`].
    pub async fn stream<H, F>(
        &self,
        deadline: std::time::Instant,
        write_timeout: Duration,
        work: F,
    ) -> Result<(H, axum::body::Body), ApiError>
    where
        F: FnOnce(Cancel, &mut ReplyWriter<H>) -> Result<(), ApiError> + Send + 'static,
        H: Send + 'static,
    {
        let permit = self.slot().await?;
        let span = tracing::Span::current();
        let (tx, rx) = reply::queue();
        let gone = tx.clone();
        let all = self.stop_all.clone();
        // Until the reply streams, the time limit answers (503 `timeout`) and drops the
        // queue; from then on the deadline stops the work here.
        let streaming = Arc::new(AtomicBool::new(false));
        let started = streaming.clone();
        let cancel = Cancel::new(move || {
            gone.is_closed()
                || all.load(Ordering::Acquire)
                || (started.load(Ordering::Acquire) && std::time::Instant::now() >= deadline)
        });
        let mut writer = ReplyWriter::new(
            tx,
            tokio::runtime::Handle::current(),
            write_timeout,
            deadline,
            streaming,
        );
        let mean = self.mean_work_us.clone();
        tokio::task::spawn_blocking(move || {
            let _permit = permit;
            let _entered = span.enter();
            let result = Self::timed(&mean, || {
                std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| work(cancel, &mut writer)))
            });
            writer.end(result.unwrap_or_else(|payload| {
                panicked(payload.as_ref());
                Err(ApiError::internal())
            }));
        });
        reply::receive(rx).await
    }
}

/// Logs a panic of request work (a bug); the client gets a generic 500.
fn panicked(payload: &(dyn std::any::Any + Send)) {
    let what = super::error::panic_text(payload);
    tracing::error!(panic = %what, "request computation panicked");
}
