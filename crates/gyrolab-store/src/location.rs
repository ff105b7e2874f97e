//! Store locations: one parser for every way a store is named (docs/STORE.md "Where the store
//! is"), so that no message ever shows a password and no URL is ever taken for a file name.
//!
//! - `postgres://` and `postgresql://` (any case: RFC 3986 schemes are case-insensitive): a
//!   PostgreSQL server. The user information is everything between `//` and the **last** `@` of
//!   the location (so a password holding `@`, `:`, `/`, `?`, `#` or `%` is taken whole; an `@` in
//!   the database name or an option must be written `%40`). Its first `:` splits user from
//!   password; both are percent-decoded where a `%` starts a valid escape (a lone `%` is kept)
//!   and re-encoded for the client.
//! - `sqlite://PATH` (any case): the SQLite file PATH (`sqlite:///abs/file.db`, `sqlite://rel.db`).
//! - libpq keyword strings (`host=... dbname=... password=...`: the location begins with a word
//!   and `=`): a PostgreSQL server, each keyword checked by the client.
//! - Refused, naming the scheme and nothing else: a scheme followed by `://` that is none of the
//!   above (`postgress://`, `postgre://`, `http://`), a scheme near `postgres` without `//`
//!   (`postgres:db`), and any other location holding `password=`.
//! - Anything else: an SQLite file path.
//!
//! Shown names mask the whole user information (user and password) as `***`, every query
//! (`?...`, which may hold `password=`) as `?***`, and every keyword string's `password` value.

/// A parsed store location.
#[derive(Clone, PartialEq, Eq)]
pub enum Location {
    /// An SQLite file.
    Sqlite {
        /// The file's path as given (after `sqlite://`, when written so).
        path: String,
    },
    /// A PostgreSQL server.
    Postgres {
        /// What the client parses (a URL with the scheme lower-cased and the user information
        /// percent-encoded, or the keyword string as given). Holds the password: never shown.
        connect: String,
        /// The password (decoded), to mask in the server's and client's messages.
        password: Option<String>,
        /// The name shown in messages (user information, query and password masked).
        shown: String,
    },
}

impl std::fmt::Debug for Location {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        // Never the password, even in a debug print.
        write!(f, "Location({})", self.shown())
    }
}

impl Location {
    /// The name to show in messages: never any part of a password.
    pub fn shown(&self) -> &str {
        match self {
            Location::Sqlite { path } => path,
            Location::Postgres { shown, .. } => shown,
        }
    }

    /// True for a PostgreSQL server.
    pub fn is_postgres(&self) -> bool {
        matches!(self, Location::Postgres { .. })
    }

    /// `message` with every occurrence of the password (as given and as decoded, percent-encoded
    /// and not) replaced by `***`.
    pub fn mask(&self, message: &str) -> String {
        let Location::Postgres { password: Some(p), connect, .. } = self else { return message.to_string() };
        let mut out = message.to_string();
        let mut forms = vec![p.clone(), percent_encode(p)];
        if let Some(raw) = raw_url_password(connect) {
            forms.push(raw);
        }
        forms.sort_by_key(|f| std::cmp::Reverse(f.len()));
        for f in forms.iter().filter(|f| !f.is_empty()) {
            out = out.replace(f.as_str(), "***");
        }
        out
    }
}

/// Why a location was refused. Its text names the scheme or what is wrong, never a password.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LocationError {
    /// The location as it may be shown (masked; a refused scheme shows only `SCHEME://...`).
    pub shown: String,
    /// What is wrong.
    pub message: String,
}

const POSTGRES_SCHEMES: [&str; 2] = ["postgres", "postgresql"];

/// The scheme of `s` per RFC 3986 (`ALPHA *( ALPHA / DIGIT / "+" / "-" / "." ) ":"`), two
/// characters or more (so that `C:` of a Windows path is no scheme), and whether `//` follows.
fn scheme_of(s: &str) -> Option<(&str, bool)> {
    let colon = s.find(':')?;
    let scheme = &s[..colon];
    let mut chars = scheme.chars();
    let first = chars.next()?;
    if scheme.len() < 2
        || !first.is_ascii_alphabetic()
        || !chars.all(|c| c.is_ascii_alphanumeric() || matches!(c, '+' | '-' | '.'))
    {
        return None;
    }
    Some((scheme, s[colon + 1..].starts_with("//")))
}

/// Levenshtein distance (ASCII, short strings).
fn distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut cur = vec![i + 1];
        for (j, cb) in b.iter().enumerate() {
            cur.push((prev[j] + usize::from(ca != *cb)).min(prev[j + 1] + 1).min(cur[j] + 1));
        }
        prev = cur;
    }
    prev[b.len()]
}

/// True when a (lower-case) scheme looks like a mistyped `postgres`/`postgresql`.
fn near_postgres(scheme: &str) -> bool {
    scheme.starts_with("postg")
        || scheme.starts_with("pg")
        || scheme == "psql"
        || POSTGRES_SCHEMES.iter().any(|p| distance(scheme, p) <= 2)
}

/// True when `s` begins like a libpq keyword string (`word =`).
fn is_keyword_string(s: &str) -> bool {
    let t = s.trim_start();
    let key_len = t.chars().take_while(|c| c.is_ascii_alphanumeric() || *c == '_').count();
    key_len > 0 && t[key_len..].trim_start().starts_with('=')
}

/// The keyword/value pairs of a libpq keyword string (values unquoted), or why not (never
/// quoting a value).
fn keyword_pairs(s: &str) -> Result<Vec<(String, String)>, String> {
    let mut out = Vec::new();
    let mut it = s.chars().peekable();
    loop {
        while it.peek().is_some_and(|c| c.is_whitespace()) {
            it.next();
        }
        if it.peek().is_none() {
            return Ok(out);
        }
        let mut key = String::new();
        while let Some(&c) = it.peek() {
            if c.is_ascii_alphanumeric() || c == '_' {
                key.push(c);
                it.next();
            } else {
                break;
            }
        }
        while it.peek().is_some_and(|c| c.is_whitespace()) {
            it.next();
        }
        if key.is_empty() || it.next() != Some('=') {
            return Err(format!("a keyword string must be `keyword=value ...` (after {} keyword(s))", out.len()));
        }
        while it.peek().is_some_and(|c| c.is_whitespace()) {
            it.next();
        }
        let mut value = String::new();
        if it.peek() == Some(&'\'') {
            it.next();
            loop {
                match it.next() {
                    Some('\\') => match it.next() {
                        Some(c) => value.push(c),
                        None => return Err(format!("the value of `{key}` has no closing quote")),
                    },
                    Some('\'') => break,
                    Some(c) => value.push(c),
                    None => return Err(format!("the value of `{key}` has no closing quote")),
                }
            }
        } else {
            while let Some(&c) = it.peek() {
                if c.is_whitespace() {
                    break;
                }
                if c == '\\' {
                    it.next();
                    if let Some(n) = it.next() {
                        value.push(n);
                    }
                    continue;
                }
                value.push(c);
                it.next();
            }
        }
        out.push((key, value));
    }
}

/// Percent-decodes `s` where a `%` starts a valid escape; other `%` are kept. Invalid UTF-8 is
/// replaced (U+FFFD).
fn percent_decode_lenient(s: &str) -> String {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' && i + 2 < b.len() {
            let hex = |c: u8| (c as char).to_digit(16);
            if let (Some(h), Some(l)) = (hex(b[i + 1]), hex(b[i + 2])) {
                out.push((h * 16 + l) as u8);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// Percent-encodes every byte outside RFC 3986's unreserved set.
fn percent_encode(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for &c in s.as_bytes() {
        if c.is_ascii_alphanumeric() || matches!(c, b'-' | b'.' | b'_' | b'~') {
            out.push(c as char);
        } else {
            out.push_str(&format!("%{c:02X}"));
        }
    }
    out
}

/// The password of a normalised URL as written in it (percent-encoded), if any.
fn raw_url_password(connect: &str) -> Option<String> {
    let rest = connect.split_once("://")?.1;
    let at = rest.rfind('@')?;
    rest[..at].split_once(':').map(|(_, p)| p.to_string())
}

/// Parses a store location (see the module's documentation): an SQLite path or a PostgreSQL
/// server, or why it is refused. Nothing returned or refused ever shows any part of a password.
pub fn parse_location(location: &str) -> Result<Location, LocationError> {
    if let Some((scheme, slashes)) = scheme_of(location) {
        let lower = scheme.to_ascii_lowercase();
        let after = &location[scheme.len() + 1..];
        if slashes && POSTGRES_SCHEMES.contains(&lower.as_str()) {
            return Ok(postgres_url(&lower, &after[2..]));
        }
        if slashes && lower == "sqlite" {
            let path = &after[2..];
            if path.is_empty() {
                return Err(LocationError {
                    shown: "sqlite://".into(),
                    message: "no file path after sqlite://".into(),
                });
            }
            return parse_location_path(path, location);
        }
        if slashes || near_postgres(&lower) {
            let hint = if near_postgres(&lower) {
                " (did you mean postgres://user:password@host/db?)"
            } else {
                " (a store is a file path, sqlite://PATH, postgres://... or postgresql://...)"
            };
            return Err(LocationError {
                shown: format!("{scheme}://..."),
                message: format!("unknown store scheme '{scheme}'{hint}; not taken as a file name"),
            });
        }
    }
    parse_location_path(location, location)
}

fn parse_location_path(path: &str, whole: &str) -> Result<Location, LocationError> {
    if is_keyword_string(whole) {
        return keyword_location(whole);
    }
    if whole.to_ascii_lowercase().contains("password=") {
        return Err(LocationError {
            shown: "(a location holding password=)".into(),
            message: "this location holds `password=` but is neither a postgres:// URL nor a libpq keyword string; \
                      not taken as a file name"
                .into(),
        });
    }
    Ok(Location::Sqlite { path: path.to_string() })
}

fn keyword_location(s: &str) -> Result<Location, LocationError> {
    let pairs = keyword_pairs(s).map_err(|m| LocationError {
        shown: "(a libpq keyword string)".into(),
        message: format!("a libpq keyword string that cannot be read: {m}; not taken as a file name"),
    })?;
    let password = pairs.iter().find(|(k, _)| k == "password").map(|(_, v)| v.clone()).filter(|p| !p.is_empty());
    let shown = pairs
        .iter()
        .map(|(k, v)| if k == "password" { format!("{k}=***") } else { format!("{k}={v}") })
        .collect::<Vec<_>>()
        .join(" ");
    Ok(Location::Postgres { connect: s.to_string(), password, shown })
}

fn postgres_url(scheme: &str, rest: &str) -> Location {
    let (userinfo, host_and_path) = match rest.rfind('@') {
        Some(at) => (Some(&rest[..at]), &rest[at + 1..]),
        None => (None, rest),
    };
    let (user, password) = match userinfo {
        Some(u) => match u.split_once(':') {
            Some((user, pw)) => (Some(percent_decode_lenient(user)), Some(percent_decode_lenient(pw))),
            None => (Some(percent_decode_lenient(u)), None),
        },
        None => (None, None),
    };
    let mut connect = format!("{scheme}://");
    if let Some(u) = &user {
        connect.push_str(&percent_encode(u));
        if let Some(p) = &password {
            connect.push(':');
            connect.push_str(&percent_encode(p));
        }
        connect.push('@');
    }
    connect.push_str(host_and_path);
    let visible = match host_and_path.find(['?', '#']) {
        Some(q) => format!("{}?***", &host_and_path[..q]),
        None => host_and_path.to_string(),
    };
    let shown = match userinfo {
        Some(_) => format!("{scheme}://***@{visible}"),
        None => format!("{scheme}://{visible}"),
    };
    // A password given as a query parameter is masked in messages as well.
    let password = password.filter(|p| !p.is_empty()).or_else(|| {
        let query = host_and_path.split_once('?')?.1;
        query.split('&').find_map(|kv| {
            let (k, v) = kv.split_once('=')?;
            (percent_decode_lenient(k) == "password").then(|| percent_decode_lenient(v)).filter(|p| !p.is_empty())
        })
    });
    Location::Postgres { connect, password, shown }
}

/// The name of `location` as messages show it (see [`parse_location`]); a refused location
/// shows only what its refusal shows.
pub fn shown_name(location: &str) -> String {
    match parse_location(location) {
        Ok(l) => l.shown().to_string(),
        Err(e) => e.shown,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const ODD: &str = "postgres://odd:p@ss:w/rd?x#y%@host/db";

    fn all_text(l: &str) -> String {
        match parse_location(l) {
            Ok(loc) => format!("{} {:?}", loc.shown(), loc),
            Err(e) => format!("{} {} {:?}", e.shown, e.message, e),
        }
    }

    #[test]
    fn odd_password_masked_whole_and_kept_for_the_client() {
        let l = parse_location(ODD).unwrap();
        assert_eq!(l.shown(), "postgres://***@host/db");
        let Location::Postgres { connect, password, .. } = &l else { panic!() };
        assert_eq!(password.as_deref(), Some("p@ss:w/rd?x#y%"));
        let config: postgres::Config = connect.parse().unwrap();
        assert_eq!(config.get_password(), Some(&b"p@ss:w/rd?x#y%"[..]));
        assert_eq!(config.get_user(), Some("odd"));
        assert_eq!(config.get_dbname(), Some("db"));
        for piece in ["p@ss", "ss:w", "w/rd", "rd?x", "x#y", "odd"] {
            assert!(!all_text(ODD).contains(piece), "{piece} in {}", all_text(ODD));
        }
        assert_eq!(
            l.mask("auth failed for p@ss:w/rd?x#y% and p%40ss%3Aw%2Frd%3Fx%23y%25"),
            "auth failed for *** and ***"
        );
    }

    #[test]
    fn schemes_are_case_insensitive_and_typos_refused() {
        let l = parse_location("POSTGRES://u:secret1@h:5432/db").unwrap();
        assert!(l.is_postgres());
        assert_eq!(l.shown(), "postgres://***@h:5432/db");
        assert!(parse_location("PostgreSQL://h/db").unwrap().is_postgres());
        for typo in [
            "postgress://u:secret1@h/db",
            "postgre://u:secret1@h/db",
            "POSTGRESS://u:secret1@h/db",
            "postgresq://u:secret1@h/db",
            "pg://u:secret1@h/db",
            "postgres:u:secret1@h/db",
        ] {
            let e = parse_location(typo).unwrap_err();
            let scheme = typo.split(':').next().unwrap();
            assert!(
                e.message.contains(&format!("'{scheme}'")) && e.message.contains("not taken as a file name"),
                "{e:?}"
            );
            assert!(!all_text(typo).contains("secret1"), "{}", all_text(typo));
        }
        let e = parse_location("http://u:secret1@h/x.db").unwrap_err();
        assert!(e.message.contains("'http'") && !all_text("http://u:secret1@h/x.db").contains("secret1"));
    }

    #[test]
    fn sqlite_paths_and_urls() {
        assert_eq!(parse_location("/tmp/gyrolab.db").unwrap(), Location::Sqlite { path: "/tmp/gyrolab.db".into() });
        assert_eq!(parse_location("SQLite:///tmp/x.db").unwrap(), Location::Sqlite { path: "/tmp/x.db".into() });
        assert_eq!(parse_location("rel/x.db").unwrap(), Location::Sqlite { path: "rel/x.db".into() });
        assert_eq!(parse_location("C:\\lab\\x.db").unwrap(), Location::Sqlite { path: "C:\\lab\\x.db".into() });
        assert!(parse_location("sqlite://").is_err());
    }

    #[test]
    fn keyword_strings_are_postgres_never_files() {
        let k = "host=127.0.0.1 port=5432 dbname=lab user=odd password='s3 cr\\'et' sslmode=disable";
        let l = parse_location(k).unwrap();
        assert!(l.is_postgres());
        assert_eq!(l.shown(), "host=127.0.0.1 port=5432 dbname=lab user=odd password=*** sslmode=disable");
        assert!(!all_text(k).contains("s3 cr"));
        let Location::Postgres { password, .. } = &l else { panic!() };
        assert_eq!(password.as_deref(), Some("s3 cr'et"));
        let e = parse_location("host=h password='unterminated-secret").unwrap_err();
        assert!(!all_text("host=h password='unterminated-secret").contains("unterminated-secret"), "{e:?}");
        let e = parse_location("/tmp/x.db password=hunter2").unwrap_err();
        assert!(
            e.message.contains("not taken as a file name")
                && !all_text("/tmp/x.db password=hunter2").contains("hunter2")
        );
    }

    #[test]
    fn queries_and_plain_urls() {
        assert_eq!(shown_name("postgres://h/db"), "postgres://h/db");
        assert_eq!(shown_name("postgres://u@h/db?password=secret2&x=1"), "postgres://***@h/db?***");
        assert_eq!(shown_name("postgresql://u:p%40ss@h/db?sslmode=disable"), "postgresql://***@h/db?***");
        let l = parse_location("postgresql://u:p%40ss@h/db").unwrap();
        let Location::Postgres { password, connect, .. } = &l else { panic!() };
        assert_eq!(password.as_deref(), Some("p@ss"));
        let config: postgres::Config = connect.parse().unwrap();
        assert_eq!(config.get_password(), Some(&b"p@ss"[..]));
    }
}
