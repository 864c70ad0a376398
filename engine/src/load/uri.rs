//! glTF URIs and buffers: which URIs a file may use, and reading what they point to.
//!
//! A glTF may only read files inside its own folder. [`classify`] accepts `data:` URIs and
//! relative paths without `..`, and refuses absolute paths, other schemes (`http:`,
//! `file:`, drive letters) and anything that percent-decodes to one of those. The loader
//! runs it on every buffer and image URI before reading any of them; [`read_relative`]
//! then also refuses a symbolic link that leads out of the folder. [`load_buffers`] does
//! both for a whole document and checks each declared `byteLength` against the data.

use super::{Files, LoadError};
use ::gltf::Document;
use std::borrow::Cow;
use std::path::{Component, Path, PathBuf};

/// The largest glTF buffer accepted (its `byteLength`).
pub const MAX_BUFFER_BYTES: u64 = 1 << 30;

/// What a URI refers to.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) enum Uri<'a> {
    /// `data:[mime][;base64],payload`.
    Data {
        mime: Option<&'a str>,
        base64: bool,
        payload: &'a str,
    },
    /// A path relative to the glTF's folder (percent-decoded, checked).
    Relative(PathBuf),
}

/// Sorts a URI into an allowed kind, or says why it is refused.
pub(crate) fn classify(uri: &str) -> Result<Uri<'_>, String> {
    if uri.is_empty() {
        return Err("empty URI".into());
    }
    // Compared as bytes: a URI may have a multi-byte character within its first five.
    if uri
        .as_bytes()
        .get(..5)
        .is_some_and(|b| b.eq_ignore_ascii_case(b"data:"))
    {
        let rest = &uri[5..];
        let (head, payload) = rest
            .split_once(',')
            .ok_or_else(|| "data: URI without a ','".to_string())?;
        let base64 = head.ends_with(";base64");
        let mime = head.strip_suffix(";base64").unwrap_or(head);
        let mime = (!mime.is_empty()).then_some(mime);
        return Ok(Uri::Data {
            mime,
            base64,
            payload,
        });
    }
    // A scheme is letters etc. followed by ':' before any '/', '?' or '#'.
    let first = uri.split(['/', '?', '#']).next().unwrap_or("");
    if first.contains(':') {
        return Err(format!(
            "URI '{}' has a scheme; only data: URIs and relative paths are allowed",
            short(uri)
        ));
    }
    let decoded = percent_decode(uri)?;
    if decoded.contains('\0') {
        return Err("URI contains a NUL byte".into());
    }
    if decoded.starts_with('/') || decoded.starts_with('\\') || decoded.contains(':') {
        return Err(format!(
            "URI '{}' is an absolute path; only paths inside the glTF's folder are allowed",
            short(uri)
        ));
    }
    let path = PathBuf::from(decoded.replace('\\', "/"));
    for c in path.components() {
        match c {
            Component::Normal(_) | Component::CurDir => {}
            Component::ParentDir => {
                return Err(format!(
                    "URI '{}' leaves the glTF's folder ('..'); not allowed",
                    short(uri)
                ))
            }
            Component::RootDir | Component::Prefix(_) => {
                return Err(format!(
                    "URI '{}' is an absolute path; only paths inside the glTF's folder are allowed",
                    short(uri)
                ))
            }
        }
    }
    Ok(Uri::Relative(path))
}

/// The first 80 characters of a URI, for messages (data: URIs can be megabytes).
fn short(uri: &str) -> String {
    match uri.char_indices().nth(80) {
        Some((i, _)) => format!("{}...", &uri[..i]),
        None => uri.to_string(),
    }
}

fn percent_decode(s: &str) -> Result<String, String> {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' {
            let hex = b
                .get(i + 1..i + 3)
                .and_then(|h| std::str::from_utf8(h).ok())
                .and_then(|h| u8::from_str_radix(h, 16).ok())
                .ok_or_else(|| format!("bad percent escape in URI '{}'", short(s)))?;
            out.push(hex);
            i += 3;
        } else {
            out.push(b[i]);
            i += 1;
        }
    }
    String::from_utf8(out).map_err(|_| format!("URI '{}' is not UTF-8 once decoded", short(s)))
}

/// Decodes standard base64 (padding optional, ASCII whitespace ignored).
pub(crate) fn base64_decode(s: &str) -> Result<Vec<u8>, String> {
    fn val(c: u8) -> Option<u32> {
        Some(match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' | b'-' => 62,
            b'/' | b'_' => 63,
            _ => return None,
        } as u32)
    }
    let mut out = Vec::with_capacity(s.len() / 4 * 3 + 3);
    let (mut acc, mut bits) = (0u32, 0u32);
    let mut padding = false;
    for &c in s.as_bytes() {
        if c.is_ascii_whitespace() {
            continue;
        }
        if c == b'=' {
            padding = true;
            continue;
        }
        if padding {
            return Err("base64 data continues after '=' padding".into());
        }
        let v = val(c).ok_or_else(|| format!("invalid base64 character {:?}", c as char))?;
        acc = (acc << 6) | v;
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
            acc &= (1 << bits) - 1;
        }
    }
    if bits >= 6 {
        return Err("truncated base64 data".into());
    }
    Ok(out)
}

/// Decodes a data: URI's payload (base64 or percent-encoded).
pub(crate) fn data_bytes(base64: bool, payload: &str) -> Result<Vec<u8>, String> {
    if base64 {
        base64_decode(payload)
    } else {
        percent_decode(payload).map(String::into_bytes)
    }
}

/// Checks every URI and declared buffer size, then reads the buffers.
pub(crate) fn load_buffers<'b>(
    path: &Path,
    dir: &Path,
    doc: &Document,
    blob: Option<&'b [u8]>,
    files: &dyn Files,
) -> Result<Vec<Cow<'b, [u8]>>, LoadError> {
    let bad = |what: String| LoadError::invalid(path, what);
    let mut uris = Vec::new();
    for b in doc.buffers() {
        let i = b.index();
        if b.length() as u64 > MAX_BUFFER_BYTES {
            return Err(bad(format!(
                "buffer {i}: byteLength {} is over the {MAX_BUFFER_BYTES}-byte limit",
                b.length()
            )));
        }
        uris.push(match b.source() {
            ::gltf::buffer::Source::Bin => None,
            ::gltf::buffer::Source::Uri(u) => {
                Some(classify(u).map_err(|r| bad(format!("buffer {i}: {r}")))?)
            }
        });
    }
    for img in doc.images() {
        if let ::gltf::image::Source::Uri { uri, .. } = img.source() {
            classify(uri).map_err(|r| bad(format!("image {}: {r}", img.index())))?;
        }
    }
    let mut out = Vec::with_capacity(uris.len());
    for (b, uri) in doc.buffers().zip(uris) {
        let (i, len) = (b.index(), b.length());
        let data: Cow<[u8]> = match uri {
            None => {
                let blob = blob.ok_or_else(|| {
                    bad(format!(
                        "buffer {i} has no uri and there is no GLB binary chunk"
                    ))
                })?;
                Cow::Borrowed(blob)
            }
            Some(Uri::Data {
                base64, payload, ..
            }) => Cow::Owned(
                data_bytes(base64, payload).map_err(|r| bad(format!("buffer {i}: {r}")))?,
            ),
            Some(Uri::Relative(rel)) => Cow::Owned(
                files
                    .read_inside(dir, &rel, Some(len as u64), MAX_BUFFER_BYTES)
                    .map_err(|r| bad(format!("buffer {i}: {r}")))?,
            ),
        };
        if data.len() < len {
            return Err(bad(format!(
                "buffer {i}: byteLength {len} exceeds its {} bytes of data",
                data.len()
            )));
        }
        out.push(match data {
            Cow::Borrowed(d) => Cow::Borrowed(&d[..len]),
            Cow::Owned(mut d) => {
                d.truncate(len);
                Cow::Owned(d)
            }
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn classify_uris() {
        assert!(matches!(classify("a.bin"), Ok(Uri::Relative(_))));
        assert!(
            matches!(classify("sub/a%20b.png"), Ok(Uri::Relative(p)) if p == Path::new("sub/a b.png"))
        );
        assert!(matches!(
            classify("data:application/octet-stream;base64,AAAA"),
            Ok(Uri::Data { base64: true, .. })
        ));
        for bad in [
            "../secret.bin",
            "a/../../x",
            "%2e%2e/x",
            "/etc/passwd",
            "%2Fetc/passwd",
            "http://example.com/a.bin",
            "file:///etc/passwd",
            "C:/x.bin",
            "C:\\x.bin",
            "..\\x",
            "",
        ] {
            assert!(classify(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn a_multibyte_character_among_the_first_five_bytes_is_no_panic() {
        // Found by the gltf fuzz target (fuzz/artifacts, 8.4 million executions in): the
        // "data:" test sliced the URI at byte 5, inside a two-byte character.
        let uri = "data\u{196}pplication/octet-stream;base64,AAAA";
        assert!(matches!(classify(uri), Ok(Uri::Relative(_))));
        assert!(classify("d\u{e9}ta:x").is_err());
        assert!(matches!(classify("\u{1F600}"), Ok(Uri::Relative(_))));
    }

    #[test]
    fn base64() {
        assert_eq!(base64_decode("aGVsbG8=").unwrap(), b"hello");
        assert_eq!(base64_decode("aGVsbG8").unwrap(), b"hello");
        assert_eq!(base64_decode("").unwrap(), b"");
        assert!(base64_decode("a").is_err());
        assert!(base64_decode("a$==").is_err());
    }
}
