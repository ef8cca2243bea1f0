//! Who may drive the explorer: its own page, loaded from 127.0.0.1, and nothing else the
//! user's browser runs. Every request is judged on its head ([`Guard::admit`]), before any
//! byte of its body is read and before any work:
//!
//! 1. **Host** (against DNS rebinding: a site whose name resolves to 127.0.0.1 reaches the
//!    port with its own name in `Host`): exactly one `Host`, and it must be `127.0.0.1:PORT`,
//!    `localhost:PORT` or `[::1]:PORT` with the port the server listens on. Else 421.
//! 2. **The token** on every `/api/` and `/img/` request: [`TOKEN_HEADER`] must carry the
//!    process's token, 128 random bits from the operating system ([`Guard::new`]), which only
//!    the page served by this process holds (embedded in it). A cross-site page cannot read
//!    the page (no CORS is ever granted), so it cannot learn the token, and it cannot set a
//!    custom header on a cross-site request without a preflight, which is never granted
//!    either. Else 403.
//! 3. **Origin**, when a browser sends one, must be this server's own (`http://` and the
//!    request's Host). Else 403.
//! 4. **A POST's body must be `application/json`**: a cross-site form or a "simple" fetch can
//!    send `text/plain` or form types without a preflight, never JSON. Else 415.
//!
//! The page itself (`GET /`) needs no token: it is how the page gets it, and no other site
//! can read it (2). The GET routes under `/api/` and `/img/` need it too, though a
//! cross-site read of their answers is already blocked by the same-origin policy: a
//! cross-site `GET /api/trace` (an `<img>` or a `no-cors` fetch) would still make the
//! explorer work, and the token costs the page nothing.

use super::http::{Head, Reply};
use std::io::Read;

/// The header that carries the token.
pub const TOKEN_HEADER: &str = "X-Rmapgen-Token";
/// Random bytes in a token (hex-encoded in the header).
pub const TOKEN_BYTES: usize = 16;

/// The judge of requests for one server: its port and its token.
pub struct Guard {
    port: u16,
    token: String,
}

impl Guard {
    /// A guard for a server on `port`, with a fresh token from `/dev/urandom`.
    pub fn new(port: u16) -> std::io::Result<Guard> {
        let mut bytes = [0u8; TOKEN_BYTES];
        std::fs::File::open("/dev/urandom")?.read_exact(&mut bytes)?;
        Ok(Guard::with_token(port, &bytes))
    }

    /// A guard with the token of `bytes` (hex).
    pub fn with_token(port: u16, bytes: &[u8]) -> Guard {
        Guard {
            port,
            token: bytes.iter().map(|b| format!("{b:02x}")).collect(),
        }
    }

    /// The token, as the page sends it in [`TOKEN_HEADER`].
    pub fn token(&self) -> &str {
        &self.token
    }

    /// The Host values this server answers to.
    pub fn hosts(&self) -> [String; 3] {
        let p = self.port;
        [
            format!("127.0.0.1:{p}"),
            format!("localhost:{p}"),
            format!("[::1]:{p}"),
        ]
    }

    /// `Ok` when the request may go on; else the refusal (one line naming the reason).
    pub fn admit(&self, head: &Head) -> Result<(), Reply> {
        let host = match head.one("host") {
            Ok(Some(h)) => h.to_ascii_lowercase(),
            Ok(None) => return Err(Reply::error(421, "no Host header: refused")),
            Err(n) => return Err(Reply::error(421, &format!("{n} Host headers: refused"))),
        };
        if !self.hosts().contains(&host) {
            return Err(Reply::error(
                421,
                &format!(
                    "Host {} is not this server ({}): refused",
                    quoted(&host),
                    self.hosts().join(", ")
                ),
            ));
        }
        let path = head.path();
        if path.starts_with("/api/") || path.starts_with("/img/") {
            let name = TOKEN_HEADER.to_ascii_lowercase();
            match head.one(&name) {
                Ok(Some(t)) if same(t.as_bytes(), self.token.as_bytes()) => {}
                Ok(Some(_)) => {
                    return Err(Reply::error(
                        403,
                        &format!("wrong {TOKEN_HEADER}: only the explorer's own page may call its API"),
                    ))
                }
                _ => {
                    return Err(Reply::error(
                        403,
                        &format!("no {TOKEN_HEADER}: only the explorer's own page may call its API (it carries the token)"),
                    ))
                }
            }
        }
        match head.one("origin") {
            Ok(None) => {}
            Ok(Some(o)) if o.eq_ignore_ascii_case(&format!("http://{host}")) => {}
            Ok(Some(o)) => {
                return Err(Reply::error(
                    403,
                    &format!(
                        "Origin {} is not this server's (http://{host}): refused",
                        quoted(o)
                    ),
                ))
            }
            Err(n) => return Err(Reply::error(403, &format!("{n} Origin headers: refused"))),
        }
        if head.method == "POST" {
            let kind = head.one("content-type").ok().flatten().unwrap_or("");
            let media = kind.split(';').next().unwrap_or("").trim();
            if !media.eq_ignore_ascii_case("application/json") {
                return Err(Reply::error(
                    415,
                    &format!(
                        "a POST's body must be application/json, not {}",
                        if kind.is_empty() {
                            "untyped".to_string()
                        } else {
                            quoted(kind)
                        }
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// A client's value in a message: at most 64 characters, quoted.
fn quoted(v: &str) -> String {
    let mut s: String = v.chars().take(64).collect();
    if v.chars().count() > 64 {
        s.push_str("...");
    }
    format!("{s:?}")
}

/// Equal bytes, in a time that depends on the lengths alone (the token is not guessed byte by
/// byte from the answer's timing).
fn same(a: &[u8], b: &[u8]) -> bool {
    a.len() == b.len() && a.iter().zip(b).fold(0u8, |d, (x, y)| d | (x ^ y)) == 0
}

#[cfg(test)]
mod tests {
    use super::*;

    fn head(method: &str, path: &str, headers: &[(&str, &str)]) -> Head {
        Head {
            method: method.into(),
            target: path.into(),
            headers: headers
                .iter()
                .map(|(k, v)| (k.to_ascii_lowercase(), v.to_string()))
                .collect(),
        }
    }

    fn status(g: &Guard, h: &Head) -> (u16, String) {
        match g.admit(h) {
            Ok(()) => (200, String::new()),
            Err(r) => (r.status, String::from_utf8(r.body).unwrap()),
        }
    }

    #[test]
    fn only_the_servers_own_names_and_port_are_answered() {
        let g = Guard::with_token(8737, &[7; TOKEN_BYTES]);
        for host in [
            "127.0.0.1:8737",
            "localhost:8737",
            "[::1]:8737",
            "LOCALHOST:8737",
        ] {
            assert_eq!(
                status(&g, &head("GET", "/", &[("Host", host)])).0,
                200,
                "{host}"
            );
        }
        for host in [
            "evil.example.com",
            "evil.example.com:8737",
            "127.0.0.1",
            "127.0.0.1:8738",
            "localhost:87370",
            "127.0.0.2:8737",
            "",
        ] {
            let (s, m) = status(&g, &head("GET", "/", &[("Host", host)]));
            assert_eq!(s, 421, "{host}: {m}");
            assert!(m.contains("not this server"), "{m}");
        }
        assert_eq!(
            status(&g, &head("GET", "/", &[])),
            (421, r#"{"error":"no Host header: refused"}"#.into())
        );
        let two = head(
            "GET",
            "/",
            &[("Host", "127.0.0.1:8737"), ("Host", "evil.example.com")],
        );
        assert_eq!(status(&g, &two).0, 421);
    }

    #[test]
    fn the_api_and_images_need_the_token_and_the_page_does_not() {
        let g = Guard::with_token(1, &[0xab; TOKEN_BYTES]);
        let t = g.token().to_string();
        assert_eq!(t.len(), 2 * TOKEN_BYTES);
        let h = |path: &str, token: Option<&str>| {
            let mut v = vec![("Host", "127.0.0.1:1")];
            if let Some(t) = token {
                v.push((TOKEN_HEADER, t));
            }
            status(&g, &head("GET", path, &v)).0
        };
        for p in [
            "/api/schema",
            "/api/trace?id=1&x=0&y=0",
            "/img/1/model.png",
            "/api/config.toml?id=1",
        ] {
            assert_eq!(h(p, Some(&t)), 200, "{p}");
            assert_eq!(h(p, None), 403, "{p}");
            assert_eq!(h(p, Some(&t[1..])), 403, "{p}");
            assert_eq!(h(p, Some(&format!("{}0", &t[..t.len() - 1]))), 403, "{p}");
        }
        assert_eq!(h("/", None), 200);
        assert_eq!(h("/favicon.ico", None), 200);
        // Two tokens, one of them right, are refused.
        let two = head(
            "GET",
            "/api/schema",
            &[
                ("Host", "127.0.0.1:1"),
                (TOKEN_HEADER, &t),
                (TOKEN_HEADER, "x"),
            ],
        );
        assert_eq!(status(&g, &two).0, 403);
        // Fresh guards have different tokens.
        assert_ne!(
            Guard::new(1).unwrap().token(),
            Guard::new(1).unwrap().token()
        );
    }

    #[test]
    fn a_post_must_be_json_from_the_servers_own_origin() {
        let g = Guard::with_token(5, &[1; TOKEN_BYTES]);
        let t = g.token().to_string();
        let post = |kind: Option<&str>, origin: Option<&str>| {
            let mut v = vec![("Host", "localhost:5"), (TOKEN_HEADER, t.as_str())];
            if let Some(k) = kind {
                v.push(("Content-Type", k));
            }
            if let Some(o) = origin {
                v.push(("Origin", o));
            }
            status(&g, &head("POST", "/api/render", &v))
        };
        assert_eq!(post(Some("application/json"), None).0, 200);
        assert_eq!(
            post(
                Some("application/json; charset=utf-8"),
                Some("http://localhost:5")
            )
            .0,
            200
        );
        for kind in [
            "text/plain",
            "application/x-www-form-urlencoded",
            "multipart/form-data",
            "application/jsonx",
        ] {
            let (s, m) = post(Some(kind), None);
            assert_eq!(s, 415, "{kind}");
            assert!(m.contains("must be application/json"), "{m}");
        }
        assert_eq!(post(None, None).0, 415);
        for origin in [
            "http://evil.example.com",
            "null",
            "http://127.0.0.1:5",
            "https://localhost:5",
            "http://localhost:6",
        ] {
            let (s, m) = post(Some("application/json"), Some(origin));
            assert_eq!(s, 403, "{origin}");
            assert!(m.contains("is not this server's"), "{m}");
        }
    }
}
