//! Streamed replies: the computation writes its reply into a [`ReplyWriter`] on its
//! blocking thread; the writer hands chunks of [`CHUNK_BYTES`] through a queue of
//! [`QUEUE_CHUNKS`] to the connection, which sends each as it comes. A client that reads
//! slowly makes the computation wait (back-pressure), so a request holds at most about
//! `(QUEUE_CHUNKS + 1) × CHUNK_BYTES` of its reply in memory, whatever the reply's size.
//!
//! - A reply that fits in one chunk is sent whole, with `Content-Length`, and an error met
//!   before the first chunk leaves is the request's error reply (its own status).
//! - Once chunks have left, the status is sent: an error after that point cuts the reply
//!   off (HTTP/1.1: the chunked body ends without its last chunk; HTTP/2: the stream is
//!   reset), so the client sees a failed transfer, never a short reply that parses; the
//!   error is logged with the request id.
//! - The computation stops at its next poll when the client is gone (the queue is closed),
//!   when the request's time limit has passed, or when a chunk waited longer than the write
//!   timeout for room in the queue (a client that stopped reading).

use std::io;
use std::pin::Pin;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::task::{Context, Poll};
use std::time::{Duration, Instant};

use axum::body::{Body, Bytes};
use http_body::Frame;
use tokio::sync::mpsc;

use super::error::ApiError;

/// Reply bytes per chunk.
pub const CHUNK_BYTES: usize = 64 << 10;

/// Chunks waiting for the connection, at most.
pub const QUEUE_CHUNKS: usize = 4;

/// What the computation sends to the connection.
#[derive(Debug)]
pub enum Message<H> {
    /// The whole reply in one piece: what the head needs, and the body.
    Whole(H, Bytes),
    /// The head of a streamed reply; chunks follow.
    Head(H),
    /// The next chunk.
    Data(Bytes),
    /// The reply is complete.
    End,
    /// The computation failed (before the head: the error reply; after: the cut).
    Fail(ApiError),
}

/// The queue a computation writes its reply into.
pub fn queue<H>() -> (mpsc::Sender<Message<H>>, mpsc::Receiver<Message<H>>) {
    mpsc::channel(QUEUE_CHUNKS)
}

/// The blocking side of a streamed reply: buffers writes and sends them in chunks, waiting
/// for room in the queue at most the write timeout (and never past the request's deadline).
pub struct ReplyWriter<H> {
    tx: mpsc::Sender<Message<H>>,
    runtime: tokio::runtime::Handle,
    write_timeout: Duration,
    deadline: Instant,
    /// The head, until the first chunk is sent.
    head: Option<H>,
    /// Whether chunks have been sent (so the status is out); shared with the stop signal,
    /// which from then on watches the deadline (before, the time limit answers and drops
    /// the queue).
    streaming: Arc<AtomicBool>,
    buf: Vec<u8>,
}

impl<H> ReplyWriter<H> {
    /// A writer into `tx`; `runtime` runs the waits for room; `streaming` is set when the
    /// first chunk leaves.
    pub fn new(
        tx: mpsc::Sender<Message<H>>,
        runtime: tokio::runtime::Handle,
        write_timeout: Duration,
        deadline: Instant,
        streaming: Arc<AtomicBool>,
    ) -> Self {
        ReplyWriter {
            tx,
            runtime,
            write_timeout,
            deadline,
            head: None,
            streaming,
            buf: Vec::new(),
        }
    }

    fn streaming(&self) -> bool {
        self.streaming.load(Ordering::Acquire)
    }

    /// What the reply's head needs (status 200, its headers); set before the first chunk
    /// can leave, i.e. before [`CHUNK_BYTES`] are written.
    pub fn head(&mut self, head: H) {
        self.head = Some(head);
    }

    fn send(&self, message: Message<H>) -> io::Result<()> {
        let wait = self
            .write_timeout
            .min(self.deadline.saturating_duration_since(Instant::now()));
        match self
            .runtime
            .block_on(tokio::time::timeout(wait, self.tx.send(message)))
        {
            Ok(Ok(())) => Ok(()),
            Ok(Err(_closed)) => Err(io::Error::new(
                io::ErrorKind::BrokenPipe,
                "the client is gone",
            )),
            Err(_elapsed) => Err(io::Error::new(
                io::ErrorKind::TimedOut,
                "the client took no reply data within the write timeout or the time limit",
            )),
        }
    }

    /// Sends the buffered bytes as a chunk (after the head, the first time).
    fn push(&mut self) -> io::Result<()> {
        if !self.streaming() {
            let head = self.head.take().ok_or_else(|| {
                io::Error::other("a streamed reply was written before its head was set")
            })?;
            self.send(Message::Head(head))?;
            self.streaming.store(true, Ordering::Release);
        }
        let chunk = std::mem::replace(&mut self.buf, Vec::with_capacity(CHUNK_BYTES));
        self.send(Message::Data(Bytes::from(chunk)))
    }

    /// Ends the reply with the computation's result: the rest and the end, or the error.
    pub fn end(mut self, result: Result<(), ApiError>) {
        let sent = match result {
            Ok(()) if !self.streaming() => match self.head.take() {
                Some(head) => {
                    let whole = Bytes::from(std::mem::take(&mut self.buf));
                    self.send(Message::Whole(head, whole))
                }
                None => {
                    tracing::error!("a reply ended without its head");
                    self.send(Message::Fail(ApiError::internal()))
                }
            },
            Ok(()) => self.push().and_then(|()| self.send(Message::End)),
            Err(e) => self.send(Message::Fail(e)),
        };
        if let Err(e) = sent {
            // The client is gone or stopped reading; nobody is left to tell.
            tracing::debug!(error = %e, "the end of a reply was not delivered");
        }
    }
}

impl<H> io::Write for ReplyWriter<H> {
    fn write(&mut self, bytes: &[u8]) -> io::Result<usize> {
        self.buf.extend_from_slice(bytes);
        if self.buf.len() >= CHUNK_BYTES {
            self.push()?;
        }
        Ok(bytes.len())
    }

    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}

/// Waits for the start of a reply: its head and body, or the computation's error.
pub async fn receive<H: Send + 'static>(
    mut rx: mpsc::Receiver<Message<H>>,
) -> Result<(H, Body), ApiError> {
    match rx.recv().await {
        Some(Message::Whole(head, bytes)) => Ok((head, Body::from(bytes))),
        Some(Message::Head(head)) => Ok((
            head,
            Body::new(Chunks {
                rx,
                done: false,
                span: tracing::Span::current(),
            }),
        )),
        Some(Message::Fail(e)) => Err(e),
        Some(Message::Data(_) | Message::End) | None => {
            tracing::error!("a reply ended before its head");
            Err(ApiError::internal())
        }
    }
}

/// The body of a streamed reply: the chunks as they come; an error when the computation
/// failed or vanished before [`Message::End`].
struct Chunks<H> {
    rx: mpsc::Receiver<Message<H>>,
    done: bool,
    /// The request's span (its id, method and path), for the log of a cut.
    span: tracing::Span,
}

impl<H> http_body::Body for Chunks<H> {
    type Data = Bytes;
    type Error = io::Error;

    fn poll_frame(
        mut self: Pin<&mut Self>,
        cx: &mut Context<'_>,
    ) -> Poll<Option<Result<Frame<Bytes>, io::Error>>> {
        if self.done {
            return Poll::Ready(None);
        }
        let message = match self.rx.poll_recv(cx) {
            Poll::Pending => return Poll::Pending,
            Poll::Ready(m) => m,
        };
        let cut = match message {
            Some(Message::Data(bytes)) => return Poll::Ready(Some(Ok(Frame::data(bytes)))),
            Some(Message::End) => {
                self.done = true;
                return Poll::Ready(None);
            }
            Some(Message::Fail(e)) => format!("{}: {}", e.code, e.message),
            Some(Message::Head(_) | Message::Whole(..)) => "a second head".to_owned(),
            None => "the computation ended without finishing its reply".to_owned(),
        };
        self.done = true;
        self.span
            .in_scope(|| tracing::warn!(cause = %cut, "a streamed reply was cut off"));
        Poll::Ready(Some(Err(io::Error::other(cut))))
    }

    fn is_end_stream(&self) -> bool {
        self.done
    }
}
