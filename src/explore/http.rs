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

/// The bounds a server reads requests under: the constants above, and the largest body.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Bounds {
    pub max_body: u64,
    pub connections: usize,
    pub deadline: Duration,
    pub write_timeout: Duration,
    pub linger: Duration,
    pub linger_bytes: u64,
}

impl Bounds {
    /// The constants above, bodies of at most `max_body` bytes.
    pub const fn new(max_body: u64) -> Bounds {
        Bounds {
            max_body,
            connections: MAX_CONNECTIONS,
            deadline: REQUEST_DEADLINE,
            write_timeout: WRITE_TIMEOUT,
            linger: LINGER,
            linger_bytes: LINGER_BYTES,
        }
    }
}

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

/// Serves `listener` with `handler` under `bounds` until the process ends. Returns only if
/// accepting fails for a reason other than a client's.
pub fn serve<H: Handler>(
    listener: TcpListener,
    bounds: Bounds,
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
        if live.fetch_add(1, Ordering::SeqCst) >= bounds.connections {
            live.fetch_sub(1, Ordering::SeqCst);
            busy(stream, bounds.connections);
            continue;
        }
        let slot = Slot(live.clone());
        let h = handler.clone();
        let spawned = std::thread::Builder::new()
            .name("rmapgen-explore-conn".into())
            .spawn(move || {
                let _slot = slot;
                connection(stream, &bounds, &*h);
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
fn busy(mut stream: TcpStream, connections: usize) {
    stream
        .set_write_timeout(Some(Duration::from_millis(100)))
        .ok();
    let r = Reply::error(
        503,
        &format!("busy: {connections} connections are open; try again"),
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
fn connection(mut stream: TcpStream, bounds: &Bounds, handler: &dyn Handler) {
    stream.set_nodelay(true).ok();
    if stream
        .set_write_timeout(Some(bounds.write_timeout))
        .is_err()
    {
        return;
    }
    let deadline = Instant::now() + bounds.deadline;
    let (reply, unread) = match request(&mut stream, bounds, deadline, handler) {
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
        linger(&mut stream, bounds);
    }
}

/// Reads and discards what the client still sends, for at most the bounds' linger time and
/// bytes ([`LINGER`], [`LINGER_BYTES`]), then returns (and the connection closes).
fn linger(stream: &mut TcpStream, bounds: &Bounds) {
    let end = Instant::now() + bounds.linger;
    let mut left = bounds.linger_bytes;
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
    bounds: &Bounds,
    deadline: Instant,
    handler: &dyn Handler,
) -> Result<Reply, Bad> {
    let max_body = bounds.max_body;
    let late = || late(bounds);
    let mut buf = Vec::with_capacity(2048);
    let end = read_head(stream, &mut buf, deadline, &late)?;
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
        let n = timed_read(stream, &mut chunk[..want], deadline, &late)?;
        body.extend_from_slice(&chunk[..n]);
    }
    Ok(handler.answer(&head, body))
}

/// The answer to a request not whole by its deadline.
fn late(bounds: &Bounds) -> Bad {
    Bad::Answer(Reply::error(
        408,
        &format!(
            "the request did not arrive whole within {} s",
            bounds.deadline.as_secs_f64()
        ),
    ))
}

/// One read of at most `buf.len()` bytes before `deadline`; `Err` on the deadline (`timeout`,
/// 408), an early close or an error.
fn timed_read(
    stream: &mut TcpStream,
    buf: &mut [u8],
    deadline: Instant,
    timeout: &dyn Fn() -> Bad,
) -> Result<usize, Bad> {
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
fn read_head(
    stream: &mut TcpStream,
    buf: &mut Vec<u8>,
    deadline: Instant,
    timeout: &dyn Fn() -> Bad,
) -> Result<usize, Bad> {
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
        let n = timed_read(stream, &mut chunk[..room], deadline, timeout)?;
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

    /// A handler that refuses a head with `x-refuse`, and answers the method, the path and
    /// the body's length.
    struct Echo;

    impl Handler for Echo {
        fn admit(&self, head: &Head) -> Result<(), Reply> {
            match head.one("x-refuse") {
                Ok(None) => Ok(()),
                _ => Err(Reply::error(403, "refused")),
            }
        }

        fn answer(&self, head: &Head, body: Vec<u8>) -> Reply {
            let text = format!("{} {} {}", head.method, head.path(), body.len());
            Reply::new(200, "text/plain", text.into_bytes())
        }
    }

    const TEST: Bounds = Bounds {
        max_body: 100,
        connections: 3,
        deadline: Duration::from_millis(500),
        write_timeout: Duration::from_secs(5),
        linger: Duration::from_millis(300),
        linger_bytes: 1 << 20,
    };

    /// A server of [`Echo`] under `bounds`; its address.
    fn echo(bounds: Bounds) -> String {
        let l = TcpListener::bind(("127.0.0.1", 0)).unwrap();
        let addr = l.local_addr().unwrap().to_string();
        std::thread::spawn(move || serve(l, bounds, Arc::new(Echo)));
        addr
    }

    /// The whole answer to `request` (the server closes after it), within a minute.
    /// One request on its own connection, its whole answer. A connection the server has
    /// answered may hold its slot a moment after the client saw the answer (its thread ends
    /// after the close): a 503 for that is asked again, for at most 5 s, so that one test's
    /// requests in a row do not depend on the machine's speed. The bound itself is tested
    /// with connections held open (`connections_beyond_the_bound_are_told_busy_and_the_slots_come_back`).
    fn ask(addr: &str, request: &[u8]) -> String {
        let until = Instant::now() + Duration::from_secs(5);
        loop {
            let got = ask_once(addr, request);
            if !got.starts_with("HTTP/1.1 503 ") || Instant::now() > until {
                return got;
            }
            std::thread::sleep(Duration::from_millis(20));
        }
    }

    /// One request on its own connection, its whole answer, whatever it is.
    fn ask_once(addr: &str, request: &[u8]) -> String {
        let mut c = TcpStream::connect(addr).unwrap();
        // The server may answer and close before the request is all written.
        let _ = c.write_all(request);
        read_all(&mut c)
    }

    fn read_all(c: &mut TcpStream) -> String {
        c.set_read_timeout(Some(Duration::from_secs(60))).unwrap();
        let mut buf = Vec::new();
        c.read_to_end(&mut buf).unwrap();
        String::from_utf8_lossy(&buf).into_owned()
    }

    fn post(len: u64) -> String {
        format!("POST /p HTTP/1.1\r\nContent-Length: {len}\r\n\r\n")
    }

    #[test]
    fn a_request_is_read_whole_and_answered_once() {
        let a = echo(TEST);
        let got = ask(&a, format!("{}{}", post(5), "hello and more").as_bytes());
        assert!(got.starts_with("HTTP/1.1 200 OK\r\n"), "{got}");
        assert!(
            got.contains("\r\nContent-Length: 9\r\n") && got.contains("Connection: close"),
            "{got}"
        );
        assert!(got.ends_with("\r\n\r\nPOST /p 5"), "{got}");
        // The body in several reads; a GET without a length has none.
        let mut c = TcpStream::connect(&a).unwrap();
        c.write_all(post(100).as_bytes()).unwrap();
        for _ in 0..10 {
            std::thread::sleep(Duration::from_millis(10));
            c.write_all(&[b'x'; 10]).unwrap();
        }
        assert!(read_all(&mut c).ends_with("POST /p 100"));
        assert!(ask(&a, b"GET /g?q=1 HTTP/1.0\r\n\r\n").ends_with("GET /g 0"));
    }

    #[test]
    fn a_body_over_the_bound_is_refused_from_its_length_and_never_read() {
        let a = echo(TEST);
        // At the bound: read. One over: refused, whatever follows.
        let at = format!("{}{}", post(100), "x".repeat(100));
        assert!(ask(&a, at.as_bytes()).ends_with("POST /p 100"));
        let got = ask(&a, format!("{}{}", post(101), "x".repeat(101)).as_bytes());
        assert!(
            got.starts_with("HTTP/1.1 413 Content Too Large\r\n"),
            "{got}"
        );
        assert!(
            got.contains("at most 100 bytes; this one says 101"),
            "{got}"
        );
        // 99,999,999,999 announced and a client that keeps sending: the answer arrives, and
        // the connection closes after the linger, long before the body could.
        let mut c = TcpStream::connect(&a).unwrap();
        c.write_all(post(99_999_999_999).as_bytes()).unwrap();
        let mut w = c.try_clone().unwrap();
        let t = Instant::now();
        let sender = std::thread::spawn(move || {
            let chunk = vec![0u8; 1 << 16];
            let mut sent = 0u64;
            while t.elapsed() < Duration::from_secs(30) && w.write_all(&chunk).is_ok() {
                sent += chunk.len() as u64;
            }
            sent
        });
        let got = read_all(&mut c);
        assert!(got.starts_with("HTTP/1.1 413"), "{got}");
        let sent = sender.join().unwrap();
        assert!(t.elapsed() < Duration::from_secs(30), "{:?}", t.elapsed());
        // The linger read at most its bytes (and the kernel's buffers hold a few more).
        assert!(sent < 64 << 20, "{sent} bytes taken");
        assert!(ask(&a, b"GET / HTTP/1.1\r\n\r\n").ends_with("GET / 0"));
    }

    #[test]
    fn the_handler_judges_the_head_before_the_body_is_read() {
        let a = echo(TEST);
        let got = ask(
            &a,
            b"POST /p HTTP/1.1\r\nX-Refuse: 1\r\nContent-Length: 99999999999\r\n\r\n",
        );
        assert!(got.starts_with("HTTP/1.1 403 Forbidden\r\n"), "{got}");
        // Refused before its framing is judged too.
        let got = ask(
            &a,
            b"POST /p HTTP/1.1\r\nX-Refuse: 1\r\nTransfer-Encoding: chunked\r\n\r\n",
        );
        assert!(got.starts_with("HTTP/1.1 403"), "{got}");
    }

    #[test]
    fn framing_the_server_does_not_take_is_refused() {
        let a = echo(TEST);
        for (req, status) in [
            (
                &b"POST /p HTTP/1.1\r\nTransfer-Encoding: chunked\r\n\r\n0\r\n\r\n"[..],
                "501 Not Implemented",
            ),
            (b"POST /p HTTP/1.1\r\n\r\n", "411 Length Required"),
            (
                b"POST /p HTTP/1.1\r\nContent-Length: 1\r\nContent-Length: 2\r\n\r\nab",
                "400 Bad Request",
            ),
            (
                b"POST /p HTTP/1.1\r\nContent-Length: 0x10\r\n\r\n",
                "400 Bad Request",
            ),
            (b"GET / HTTP/2\r\n\r\n", "400 Bad Request"),
        ] {
            let got = ask(&a, req);
            assert!(got.starts_with(&format!("HTTP/1.1 {status}\r\n")), "{got}");
        }
        // A head of exactly the bound is read; one byte more is refused.
        let pad = |n: usize| format!("GET / HTTP/1.1\r\nX: {}\r\n\r\n", "a".repeat(n));
        let base = pad(0).len();
        assert!(ask(&a, pad(MAX_HEAD - base).as_bytes()).ends_with("GET / 0"));
        let got = ask(&a, pad(MAX_HEAD - base + 1).as_bytes());
        assert!(
            got.starts_with("HTTP/1.1 431 Request Header Fields Too Large\r\n"),
            "{got}"
        );
        assert!(got.contains(&format!("exceed {MAX_HEAD} bytes")), "{got}");
    }

    #[test]
    fn a_slow_client_is_answered_408_at_its_deadline_and_holds_no_one_else() {
        let a = echo(TEST);
        // A head and a body sent a byte every 100 ms: each longer than the deadline.
        let slow = |first: String, more: usize| {
            let mut c = TcpStream::connect(&a).unwrap();
            std::thread::spawn(move || {
                let t = Instant::now();
                c.write_all(first.as_bytes()).unwrap();
                for _ in 0..more {
                    std::thread::sleep(Duration::from_millis(100));
                    if c.write_all(b"x").is_err() {
                        break;
                    }
                }
                (read_all(&mut c), t.elapsed())
            })
        };
        let body = slow(post(50), 50);
        let head = slow("GET / HTTP/1.1\r\nX: ".into(), 50);
        std::thread::sleep(Duration::from_millis(100));
        assert!(ask(&a, b"GET /other HTTP/1.1\r\n\r\n").ends_with("GET /other 0"));
        assert!(!body.is_finished() && !head.is_finished());
        for h in [body, head] {
            let (got, took) = h.join().unwrap();
            assert!(got.starts_with("HTTP/1.1 408 Request Timeout\r\n"), "{got}");
            assert!(got.contains("within 0.5 s"), "{got}");
            assert!(
                took >= TEST.deadline && took < Duration::from_secs(4),
                "{took:?}"
            );
        }
    }

    #[test]
    fn connections_beyond_the_bound_are_told_busy_and_the_slots_come_back() {
        let a = echo(TEST);
        let idle: Vec<TcpStream> = (0..TEST.connections)
            .map(|_| TcpStream::connect(&a).unwrap())
            .collect();
        let got = ask_once(&a, b"GET / HTTP/1.1\r\n\r\n");
        assert!(
            got.starts_with("HTTP/1.1 503 Service Unavailable\r\n"),
            "{got}"
        );
        assert!(
            got.contains("busy: 3 connections are open") && got.contains("Retry-After: 1"),
            "{got}"
        );
        // A client that leaves early frees its slot; so does one that says nothing until
        // its deadline.
        drop(idle);
        let t = Instant::now();
        while !ask(&a, b"GET / HTTP/1.1\r\n\r\n").ends_with("GET / 0") {
            assert!(
                t.elapsed() < Duration::from_secs(10),
                "the slots stayed taken"
            );
            std::thread::sleep(Duration::from_millis(20));
        }
        // Each silent client holds a slot: one that came while a slot of the loop above was
        // still being given back was told busy at once, and is connected again.
        let t = Instant::now();
        let silent: Vec<TcpStream> = (0..TEST.connections)
            .map(|_| loop {
                let mut c = TcpStream::connect(&a).unwrap();
                c.set_read_timeout(Some(Duration::from_millis(100)))
                    .unwrap();
                let mut b = [0u8; 1];
                match c.read(&mut b) {
                    Ok(n) if n > 0 => std::thread::sleep(Duration::from_millis(20)),
                    _ => break c,
                }
            })
            .collect();
        while !ask(&a, b"GET / HTTP/1.1\r\n\r\n").ends_with("GET / 0") {
            assert!(
                t.elapsed() < Duration::from_secs(10),
                "the silent ones kept their slots"
            );
            std::thread::sleep(Duration::from_millis(20));
        }
        // Not before their deadline.
        assert!(
            t.elapsed() >= TEST.deadline - Duration::from_millis(100),
            "{:?}",
            t.elapsed()
        );
        drop(silent);
    }

    #[test]
    fn every_status_sent_has_its_reason() {
        for &(code, phrase) in STATUSES {
            assert_eq!(reason(code), phrase);
            let r = Reply::error(code, "x").bytes();
            assert!(String::from_utf8(r)
                .unwrap()
                .starts_with(&format!("HTTP/1.1 {code} {phrase}\r\n")));
        }
        assert_eq!(reason(299), "Unknown");
        let mut r = Reply::new(200, "text/toml", b"a = 1".to_vec()).with_header("X-A", "b".into());
        r.attachment = Some("f.toml");
        let text = String::from_utf8(r.bytes()).unwrap();
        assert_eq!(
            text,
            "HTTP/1.1 200 OK\r\nContent-Type: text/toml\r\nContent-Length: 5\r\nCache-Control: no-store\r\nX-Content-Type-Options: nosniff\r\nConnection: close\r\nContent-Disposition: attachment; filename=\"f.toml\"\r\nX-A: b\r\n\r\na = 1"
        );
    }
}
