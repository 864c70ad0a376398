//! Fills in what the glTF 2.0 specification makes optional but the `gltf-json` crate (1.4)
//! requires, before it parses: a scene without `nodes` (an empty scene) gets `"nodes": []`.
//! Works on `.gltf` JSON and on a GLB's JSON chunk; a file that needs nothing is passed on
//! untouched, and one that is not JSON is left for the parser to report.

use serde_json::Value;
use std::borrow::Cow;

/// `bytes` (glTF JSON or GLB) with the optional fields `gltf-json` needs filled in.
pub(crate) fn optional_fields(bytes: &[u8]) -> Cow<'_, [u8]> {
    if bytes.starts_with(b"glTF") {
        glb(bytes).map_or(Cow::Borrowed(bytes), Cow::Owned)
    } else {
        json(bytes).map_or(Cow::Borrowed(bytes), |j| Cow::Owned(j.into_bytes()))
    }
}

/// The patched JSON text, or `None` when it needs nothing (or is not JSON).
fn json(text: &[u8]) -> Option<String> {
    let mut root: Value = serde_json::from_slice(text).ok()?;
    let scenes = root.get_mut("scenes")?.as_array_mut()?;
    let mut changed = false;
    for scene in scenes.iter_mut().filter_map(Value::as_object_mut) {
        if !scene.contains_key("nodes") {
            scene.insert("nodes".into(), Value::Array(Vec::new()));
            changed = true;
        }
    }
    changed.then(|| root.to_string())
}

fn u32_at(b: &[u8], at: usize) -> Option<u32> {
    Some(u32::from_le_bytes(b.get(at..at + 4)?.try_into().ok()?))
}

/// The GLB with its JSON chunk patched (padded with spaces to 4 bytes, lengths rewritten),
/// or `None` when it needs nothing or its framing is not sound (the parser then reports it).
fn glb(bytes: &[u8]) -> Option<Vec<u8>> {
    const JSON: u32 = 0x4E4F_534A;
    let total = (u32_at(bytes, 8)? as usize).min(bytes.len());
    let len = u32_at(bytes, 12)? as usize;
    if u32_at(bytes, 16)? != JSON {
        return None;
    }
    let end = 20usize.checked_add(len).filter(|&e| e <= total)?;
    let mut patched = json(&bytes[20..end])?.into_bytes();
    while patched.len() % 4 != 0 {
        patched.push(b' ');
    }
    let rest = &bytes[end..total];
    let new_total = u32::try_from(20 + patched.len() + rest.len()).ok()?;
    let mut out = Vec::with_capacity(new_total as usize);
    out.extend_from_slice(&bytes[..8]);
    out.extend_from_slice(&new_total.to_le_bytes());
    out.extend_from_slice(&(patched.len() as u32).to_le_bytes());
    out.extend_from_slice(&JSON.to_le_bytes());
    out.extend_from_slice(&patched);
    out.extend_from_slice(rest);
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scenes_without_nodes_get_an_empty_list_and_nothing_else_changes() {
        let text = br#"{"asset":{"version":"2.0"},"scenes":[{"name":"a"},{"nodes":[0]}]}"#;
        let out = optional_fields(text);
        let v: Value = serde_json::from_slice(&out).unwrap();
        assert_eq!(v["scenes"][0]["nodes"], Value::Array(vec![]));
        assert_eq!(v["scenes"][0]["name"], "a");
        assert_eq!(v["scenes"][1]["nodes"][0], 0);
        assert_eq!(v["asset"]["version"], "2.0");
        // Nothing to do, or not JSON: the same bytes.
        let fine = br#"{"asset":{"version":"2.0"},"scenes":[{"nodes":[]}]}"#;
        assert!(matches!(optional_fields(fine), Cow::Borrowed(_)));
        assert!(matches!(optional_fields(b"{nope"), Cow::Borrowed(_)));
    }

    #[test]
    fn a_glb_keeps_its_binary_chunk_and_framing() {
        let bin = [1u8, 2, 3, 4, 5, 6, 7, 8];
        let glb =
            crate::load::fuzz::glb_container(r#"{"asset":{"version":"2.0"},"scenes":[{}]}"#, &bin);
        let out = optional_fields(&glb);
        assert_eq!(u32_at(&out, 8), Some(out.len() as u32));
        let len = u32_at(&out, 12).unwrap() as usize;
        assert_eq!(len % 4, 0);
        let v: Value = serde_json::from_slice(&out[20..20 + len]).unwrap();
        assert_eq!(v["scenes"][0]["nodes"], Value::Array(vec![]));
        assert_eq!(&out[20 + len + 8..], &bin);
        // Broken framing is left for the parser.
        let mut bad = glb.clone();
        bad[12] = 0xff;
        assert!(matches!(optional_fields(&bad), Cow::Borrowed(_)));
    }
}
