//! The explorer's HTTP/1.1 server, over `std::net` and nothing else: every byte a client
//! sends is read here, under bounds, before the explorer sees a request.
//!
//! - **One thread per connection**, at most [`MAX_CONNECTIONS`] at once; the one more is
//!   answered 503 from the accepting thread and closed. A slow client holds its own thread,
//!   never another's, and the accepting thread reads nothing.
//! - **A deadline per request**: the request line, the headers and the body must all arrive
//!   within [`REQUEST_DEADLINE`] of the connection (408 otherwise); an answer that the client
//!   does not read within [`WRITE_TIMEOUT`] is abandoned.
//! - **Bounded reads**: the request line and headers at most [`MAX_HEAD`] bytes (431), a body at
//!   most the server's `max_body` (413, from its `Content-Length` alone: no body byte is read);
//!   `Transfer-Encoding` is refused (501), so the length is always known before reading.
//! - **The handler judges the head first** ([`Handler::admit`]: the Host, the token, the
//!   Origin) and the body is read only if it admits it.
//! - **One request per connection** (`Connection: close` on every answer). A refused request
//!   whose body was not read is answered and the connection closed after a bounded linger
//!   ([`LINGER`], [`LINGER_BYTES`]): the client reads the answer instead of a reset, and a
//!   huge `Content-Length` costs a second at most, never its length.

use std::io::{ErrorKind, Read, Write};
use std::net::{Shutdown, TcpListener, TcpStream};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Largest request line and headers together: a browser's are well under 2 KB.
pub const MAX_HEAD: usize = 8 << 10;
/// Most connections served at once (each a thread while its request is read and answered).
pub const MAX_CONNECTIONS: usize = 32;
/// Time from the connection to the end of its request's body.
pub const REQUEST_DEADLINE: Duration = Duration::from_secs(10);
/// Time a client may leave an answer unread before the connection is dropped.
pub const WRITE_TIMEOUT: Duration = Duration::from_secs(10);
/// After a refusal with the body unread: how long, and how many bytes, the server reads and
/// discards before it closes (so that the client sees the answer, not a reset).
pub const LINGER: Duration = Duration::from_secs(1);
pub const LINGER_BYTES: u64 = 1 << 20;

/// A request's line and headers.
#[derive(Debug, Clone)]
pub struct Head {
    pub method: String,
    /// The request target as sent: a path and its query.
    pub target: String,
    /// Headers in order, names in lower case, values trimmed.
    pub headers: Vec<(String, String)>,
}

impl Head {
    /// Every value of header `name` (lower case).
    pub fn all<'a>(&'a self, name: &'a str) -> impl Iterator<Item = &'a str> {
        self.headers
            .iter()
            .filter(move |(n, _)| n == name)
            .map(|(_, v)| v.as_str())
    }

    /// The value of header `name` (lower case) when it is given exactly once; `Err` with
    /// the count when it is given several times.
    pub fn one<'a>(&'a self, name: &'a str) -> Result<Option<&'a str>, usize> {
        let mut it = self.all(name);
        match (it.next(), it.count()) {
            (v, 0) => Ok(v),
            (_, more) => Err(more + 1),
        }
    }

    /// The target's path, without its query.
    pub fn path(&self) -> &str {
        self.target.split('?').next().unwrap_or("")
    }
}

/// An answer: status, content type, body, an optional file name to save it as, and further
/// headers.
#[derive(Debug)]
pub struct Reply {
    pub status: u16,
    pub kind: &'static str,
    pub body: Vec<u8>,
    pub attachment: Option<&'static str>,
    pub headers: Vec<(&'static str, String)>,
}

impl Reply {
    pub fn new(status: u16, kind: &'static str, body: Vec<u8>) -> Reply {
        Reply {
            status,
            kind,
            body,
            attachment: None,
            headers: Vec::new(),
        }
    }

    /// `{"error": msg}`: every refusal is one line.
    pub fn error(status: u16, msg: &str) -> Reply {
        let v = serde_json::json!({ "error": msg });
        Reply::new(status, "application/json", v.to_string().into_bytes())
    }

    pub fn with_header(mut self, name: &'static str, value: String) -> Reply {
        self.headers.push((name, value));
        self
    }

    /// The whole answer as sent: status line, headers, body.
    fn bytes(&self) -> Vec<u8> {
        let mut h = format!(
            "HTTP/1.1 {} {}\r\nContent-Type: {}\r\nContent-Length: {}\r\nCache-Control: no-store\r\nX-Content-Type-Options: nosniff\r\nConnection: close\r\n",
            self.status,
            reason(self.status),
            self.kind,
            self.body.len()
        );
        if let Some(name) = self.attachment {
            h.push_str(&format!(
                "Content-Disposition: attachment; filename=\"{name}\"\r\n"
            ));
        }
        for (k, v) in &self.headers {
            h.push_str(&format!("{k}: {v}\r\n"));
        }
        h.push_str("\r\n");
        let mut out = h.into_bytes();
        out.extend_from_slice(&self.body);
        out
    }
}

/// Every status the explorer sends, with its reason phrase (docs/EXPLORE.md's status table
/// is checked against this list).
pub const STATUSES: &[(u16, &str)] = &[
    (200, "OK"),
    (204, "No Content"),
    (400, "Bad Request"),
    (403, "Forbidden"),
    (404, "Not Found"),
    (405, "Method Not Allowed"),
    (408, "Request Timeout"),
    (411, "Length Required"),
    (413, "Content Too Large"),
    (415, "Unsupported Media Type"),
    (421, "Misdirected Request"),
    (431, "Request Header Fields Too Large"),
    (500, "Internal Server Error"),
    (501, "Not Implemented"),
    (503, "Service Unavailable"),
];

/// The reason phrase of `status` (one of [`STATUSES`]).
fn reason(status: u16) -> &'static str {
    STATUSES
        .iter()
        .find(|s| s.0 == status)
        .map_or("Unknown", |s| s.1)
}

/// What the server asks of the application.
pub trait Handler: Send + Sync + 'static {
    /// Judges a request on its head alone, before any byte of its body is read: `Err` is
    /// the answer that refuses it.
    fn admit(&self, head: &Head) -> Result<(), Reply>;
    /// Answers an admitted request with its whole body.
    fn answer(&self, head: &Head, body: Vec<u8>) -> Reply;
}

/// Serves `listener` with `handler` until the process ends; bodies of at most `max_body`
/// bytes. Returns only if accepting fails for a reason other than a client's.
pub fn serve<H: Handler>(
    listener: TcpListener,
    max_body: u64,
    handler: Arc<H>,
) -> std::io::Result<()> {
    let live = Arc::new(AtomicUsize::new(0));
    for stream in listener.incoming() {
        let stream = match stream {
            Ok(s) => s,
            // A client that went away between its connect and our accept, or a momentary
            // lack of descriptors: the next connection may do.
            Err(e) if transient(&e) => {
                if e.raw_os_error() == Some(libc::EMFILE) || e.raw_os_error() == Some(libc::ENFILE)
                {
                    std::thread::sleep(Duration::from_millis(50));
                }
                continue;
            }
            Err(e) => return Err(e),
        };
        if live.fetch_add(1, Ordering::SeqCst) >= MAX_CONNECTIONS {
            live.fetch_sub(1, Ordering::SeqCst);
            busy(stream);
            continue;
        }
        let slot = Slot(live.clone());
        let h = handler.clone();
        let spawned = std::thread::Builder::new()
            .name("rmapgen-explore-conn".into())
            .spawn(move || {
                let _slot = slot;
                connection(stream, max_body, &*h);
            });
        // The closure (and its slot) is dropped if the thread could not start.
        drop(spawned);
    }
    Ok(())
}

/// Errors of `accept` that concern one connection, or pass.
fn transient(e: &std::io::Error) -> bool {
    matches!(
        e.kind(),
        ErrorKind::ConnectionAborted | ErrorKind::ConnectionReset | ErrorKind::Interrupted
    ) || matches!(
        e.raw_os_error(),
        Some(
            libc::EMFILE | libc::ENFILE | libc::ENOBUFS | libc::ENOMEM | libc::EPROTO | libc::EPERM
        )
    )
}

/// A counted connection; the count goes down when its thread ends, however it ends.
struct Slot(Arc<AtomicUsize>);

impl Drop for Slot {
    fn drop(&mut self) {
        self.0.fetch_sub(1, Ordering::SeqCst);
    }
}

/// The answer to a connection beyond [`MAX_CONNECTIONS`], written from the accepting thread
/// without reading anything (it fits the socket's buffer; the write cannot wait long).
fn busy(mut stream: TcpStream) {
    stream
        .set_write_timeout(Some(Duration::from_millis(100)))
        .ok();
    let r = Reply::error(
        503,
        &format!("busy: {MAX_CONNECTIONS} connections are open; try again"),
    )
    .with_header("Retry-After", "1".into());
    stream.write_all(&r.bytes()).ok();
    stream.shutdown(Shutdown::Both).ok();
}

/// Why a request could not be read.
enum Bad {
    /// The client closed before a whole request (nothing to answer).
    Gone,
    /// An answer for it.
    Answer(Reply),
}

/// One connection: its request read under the bounds, judged, answered, closed.
fn connection(mut stream: TcpStream, max_body: u64, handler: &dyn Handler) {
    stream.set_nodelay(true).ok();
    if stream.set_write_timeout(Some(WRITE_TIMEOUT)).is_err() {
        return;
    }
    let deadline = Instant::now() + REQUEST_DEADLINE;
    let (reply, unread) = match request(&mut stream, max_body, deadline, handler) {
        Ok(reply) => (reply, false),
        Err(Bad::Gone) => return,
        Err(Bad::Answer(reply)) => (reply, true),
    };
    // A client that left before the answer is not the server's failure.
    if stream.write_all(&reply.bytes()).is_ok() {
        stream.flush().ok();
    }
    stream.shutdown(Shutdown::Write).ok();
    if unread {
        linger(&mut stream);
    }
}

/// Reads and discards what the client still sends, for at most [`LINGER`] and
/// [`LINGER_BYTES`], then returns (and the connection closes).
fn linger(stream: &mut TcpStream) {
    let end = Instant::now() + LINGER;
    let mut left = LINGER_BYTES;
    let mut buf = [0u8; 8192];
    while left > 0 {
        let now = Instant::now();
        if now >= end || stream.set_read_timeout(Some(end - now)).is_err() {
            return;
        }
        match stream.read(&mut buf) {
            Ok(0) | Err(_) => return,
            Ok(n) => left = left.saturating_sub(n as u64),
        }
    }
}

/// Reads one request and has the handler answer it; `Err` when it cannot be read whole (the
/// body then unread).
fn request(
    stream: &mut TcpStream,
    max_body: u64,
    deadline: Instant,
    handler: &dyn Handler,
) -> Result<Reply, Bad> {
    let mut buf = Vec::with_capacity(2048);
    let end = read_head(stream, &mut buf, deadline)?;
    let head = parse_head(&buf[..end]).map_err(|m| Bad::Answer(Reply::error(400, &m)))?;
    handler.admit(&head).map_err(Bad::Answer)?;
    if head.all("transfer-encoding").next().is_some() {
        return Err(Bad::Answer(Reply::error(
            501,
            "Transfer-Encoding is not supported: send the body with a Content-Length",
        )));
    }
    let length = content_length(&head).map_err(|m| Bad::Answer(Reply::error(400, &m)))?;
    let length = match length {
        Some(n) => n,
        None if head.method == "POST" => {
            return Err(Bad::Answer(Reply::error(
                411,
                "a POST needs a Content-Length",
            )))
        }
        None => 0,
    };
    if length > max_body {
        return Err(Bad::Answer(Reply::error(
            413,
            &format!("a request body of at most {max_body} bytes; this one says {length}"),
        )));
    }
    // `length` is at most `max_body`: the buffer is bounded before it is allocated.
    let mut body = buf.split_off(end + 4);
    body.truncate(length as usize);
    body.reserve_exact(length as usize - body.len());
    let mut chunk = [0u8; 8192];
    while body.len() < length as usize {
        let want = (length as usize - body.len()).min(chunk.len());
        let n = timed_read(stream, &mut chunk[..want], deadline)?;
        body.extend_from_slice(&chunk[..n]);
    }
    Ok(handler.answer(&head, body))
}

/// One read of at most `buf.len()` bytes before `deadline`; `Err` on the deadline (408), an
/// early close or an error.
fn timed_read(stream: &mut TcpStream, buf: &mut [u8], deadline: Instant) -> Result<usize, Bad> {
    let timeout = || {
        Bad::Answer(Reply::error(
            408,
            &format!(
                "the request did not arrive whole within {} s",
                REQUEST_DEADLINE.as_secs()
            ),
        ))
    };
    loop {
        let now = Instant::now();
        if now >= deadline {
            return Err(timeout());
        }
        stream
            .set_read_timeout(Some(deadline - now))
            .map_err(|_| Bad::Gone)?;
        match stream.read(buf) {
            Ok(0) => return Err(Bad::Gone),
            Ok(n) => return Ok(n),
            Err(e) if e.kind() == ErrorKind::Interrupted => continue,
            Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => {
                return Err(timeout())
            }
            Err(_) => return Err(Bad::Gone),
        }
    }
}

/// Reads until the blank line that ends the head; its offset in `buf` (the body's first
/// bytes may follow it in `buf`).
fn read_head(stream: &mut TcpStream, buf: &mut Vec<u8>, deadline: Instant) -> Result<usize, Bad> {
    let mut chunk = [0u8; 2048];
    loop {
        if let Some(i) = find_end(buf) {
            return Ok(i);
        }
        if buf.len() >= MAX_HEAD {
            return Err(Bad::Answer(Reply::error(
                431,
                &format!("the request line and headers exceed {MAX_HEAD} bytes"),
            )));
        }
        let room = (MAX_HEAD - buf.len()).min(chunk.len());
        let n = timed_read(stream, &mut chunk[..room], deadline)?;
        buf.extend_from_slice(&chunk[..n]);
    }
}

/// The offset of the `\r\n\r\n` that ends a head of at most [`MAX_HEAD`] bytes (the blank
/// line included).
fn find_end(buf: &[u8]) -> Option<usize> {
    buf[..buf.len().min(MAX_HEAD)]
        .windows(4)
        .position(|w| w == b"\r\n\r\n")
}

/// A token character of RFC 9110 (method and header names).
fn tchar(c: u8) -> bool {
    c.is_ascii_alphanumeric() || b"!#$%&'*+-.^_`|~".contains(&c)
}

/// The request line and headers; `Err` names what is malformed.
fn parse_head(raw: &[u8]) -> Result<Head, String> {
    let text = std::str::from_utf8(raw).map_err(|_| "the request head is not ASCII".to_string())?;
    if !text.is_ascii() {
        return Err("the request head is not ASCII".into());
    }
    let mut lines = text.split("\r\n");
    let line = lines.next().unwrap_or("");
    let mut parts = line.split(' ');
    let (method, target, version) = match (parts.next(), parts.next(), parts.next(), parts.next()) {
        (Some(m), Some(t), Some(v), None) => (m, t, v),
        _ => return Err("a request line is METHOD TARGET HTTP/1.1".into()),
    };
    if method.is_empty() || !method.bytes().all(tchar) {
        return Err("a request line is METHOD TARGET HTTP/1.1".into());
    }
    if !target.starts_with('/') || !target.bytes().all(|c| c.is_ascii_graphic()) {
        return Err("the request target must be a path (/...)".into());
    }
    if version != "HTTP/1.1" && version != "HTTP/1.0" {
        return Err(format!(
            "HTTP/1.0 or HTTP/1.1 only, not {}",
            crate::toml_input::one_line(&version.chars().take(16).collect::<String>())
        ));
    }
    let mut headers = Vec::new();
    for l in lines {
        let Some((name, value)) = l.split_once(':') else {
            return Err("a header line is NAME: VALUE".into());
        };
        if name.is_empty() || !name.bytes().all(tchar) {
            return Err("a header name is a token, with no space before its colon".into());
        }
        if value.bytes().any(|c| c.is_ascii_control() && c != b'\t') {
            return Err(format!("header {name}: a control character in its value"));
        }
        headers.push((name.to_ascii_lowercase(), value.trim().to_string()));
    }
    Ok(Head {
        method: method.to_string(),
        target: target.to_string(),
        headers,
    })
}

/// The body's length from `Content-Length` (None when absent); several different values, or
/// one that is not a decimal number, are refused.
fn content_length(head: &Head) -> Result<Option<u64>, String> {
    let mut length = None;
    for v in head.all("content-length") {
        let n = if !v.is_empty() && v.len() <= 20 && v.bytes().all(|c| c.is_ascii_digit()) {
            v.parse::<u64>().ok()
        } else {
            None
        };
        let Some(n) = n else {
            return Err("Content-Length must be a decimal number of bytes".into());
        };
        if length.is_some_and(|l| l != n) {
            return Err("Content-Length is given twice with different values".into());
        }
        length = Some(n);
    }
    Ok(length)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_head_is_parsed_and_a_malformed_one_named() {
        let h = parse_head(
            b"POST /api/render?x=1 HTTP/1.1\r\nHost: 127.0.0.1:9\r\nContent-Length:  12 \r\nX-A: b",
        )
        .unwrap();
        assert_eq!((h.method.as_str(), h.path()), ("POST", "/api/render"));
        assert_eq!(h.one("host"), Ok(Some("127.0.0.1:9")));
        assert_eq!(content_length(&h), Ok(Some(12)));
        assert_eq!(h.one("x-a"), Ok(Some("b")));
        assert_eq!(h.one("origin"), Ok(None));
        for (raw, says) in [
            (&b"GET / HTTP/2"[..], "HTTP/1.0 or HTTP/1.1 only"),
            (b"GET  / HTTP/1.1", "METHOD TARGET"),
            (b"GET http://a/ HTTP/1.1", "must be a path"),
            (b"GET / HTTP/1.1\r\nHost : a", "no space before its colon"),
            (b"GET / HTTP/1.1\r\n folded", "NAME: VALUE"),
            (b"GET / HTTP/1.1\r\nA: b\x01", "control character"),
            (b"GET /\xc3\xa9 HTTP/1.1", "not ASCII"),
        ] {
            let e = parse_head(raw).unwrap_err();
            assert!(e.contains(says), "{e}");
        }
        let twice = |a: &str, b: &str| {
            content_length(
                &parse_head(
                    format!("GET / HTTP/1.1\r\nContent-Length: {a}\r\nContent-Length: {b}")
                        .as_bytes(),
                )
                .unwrap(),
            )
        };
        assert_eq!(twice("5", "5"), Ok(Some(5)));
        assert!(twice("5", "6").unwrap_err().contains("twice"));
        assert!(twice("5", "-6").unwrap_err().contains("decimal"));
        assert!(twice("5", "99999999999999999999999")
            .unwrap_err()
            .contains("decimal"));
        let h = parse_head(b"GET / HTTP/1.1\r\nHost: a\r\nhost: b").unwrap();
        assert_eq!(h.one("host"), Err(2));
    }

    #[test]
    fn the_end_of_a_head_is_found_within_the_bound_only() {
        assert_eq!(find_end(b"GET / HTTP/1.1\r\n\r\nbody"), Some(14));
        assert_eq!(find_end(b"GET / HTTP/1.1\r\n"), None);
        let mut at = vec![b'a'; MAX_HEAD - 4];
        at.extend_from_slice(b"\r\n\r\nbody");
        assert_eq!(find_end(&at), Some(MAX_HEAD - 4));
        at.insert(0, b'a');
        assert_eq!(find_end(&at), None);
    }
}
