//! What the mesh crates (tobj, gltf) do not check themselves, checked before they read a file:
//! where they would panic (found by tests and fuzzing) or accept without a word what cannot be
//! meant. Each error is one line naming the line, node or accessor.

use anyhow::{Result, anyhow, bail};

/// Text from a file for a message: at most 40 characters, control characters escaped.
fn clipped(text: &str) -> String {
    let mut out: String = text.chars().take(40).flat_map(char::escape_debug).collect();
    if text.chars().count() > 40 {
        out.push('…');
    }
    out
}

/// What tobj does not check in an MTL file: colour lines with fewer than three numbers
/// (tobj unwraps them and panics) and a material name defined twice. Errors give the line.
pub(crate) fn check_mtl_lines(mtl: &[u8]) -> std::result::Result<(), String> {
    let mut defined = std::collections::HashMap::new();
    for (i, line) in mtl.split(|&b| b == b'\n').enumerate() {
        let line = String::from_utf8_lossy(line);
        let mut words = line.split_whitespace();
        match words.next() {
            Some(key @ ("Ka" | "Kd" | "Ks" | "Ke")) => {
                let numbers: Vec<&str> = words.take(3).collect();
                if numbers.len() < 3 || numbers.iter().any(|w| w.parse::<f32>().is_err()) {
                    return Err(format!(
                        "line {}: `{key}` needs three numbers, got `{}`",
                        i + 1,
                        clipped(&numbers.join(" "))
                    ));
                }
            }
            Some("newmtl") => {
                let name = line.trim().split_once(' ').unwrap_or_default().1.trim();
                if let Some(first) = defined.insert(name.to_string(), i + 1) {
                    return Err(format!(
                        "line {}: material `{}` is defined twice (first at line {first})",
                        i + 1,
                        clipped(name)
                    ));
                }
            }
            _ => {}
        }
    }
    Ok(())
}

/// Every `usemtl` of an OBJ names a material of its libraries: tobj would draw an unknown one
/// in the default grey without a word.
pub(crate) fn check_usemtl_names(obj: &[u8], materials: &[&str]) -> Result<()> {
    for (i, line) in obj.split(|&b| b == b'\n').enumerate() {
        let line = String::from_utf8_lossy(line);
        if line.split_whitespace().next() != Some("usemtl") {
            continue;
        }
        let name = line.split_once(' ').unwrap_or_default().1.trim();
        if !materials.contains(&name) {
            let mut known: Vec<&str> = materials.iter().copied().take(20).collect();
            if known.is_empty() {
                known.push("none: no `mtllib` defines any");
            }
            bail!(
                "line {}: `usemtl {}` names no material of the OBJ's material libraries (defined: {})",
                i + 1,
                clipped(name),
                known.join(", ")
            );
        }
    }
    Ok(())
}

/// A GLB's 12-byte header must declare a length that holds the header and one chunk header
/// and fits the file: the gltf crate subtracts before it checks (an overflow, found by
/// fuzzing, that panics where overflow checks are on).
pub(crate) fn check_glb_header(bytes: &[u8]) -> Result<()> {
    if !bytes.starts_with(b"glTF") {
        return Ok(()); // glTF JSON
    }
    let word = |at: usize| {
        bytes
            .get(at..at + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize)
    };
    match (word(4), word(8)) {
        (Some(2), Some(length)) if (12 + 8..=bytes.len()).contains(&length) => Ok(()),
        (Some(2), Some(length)) => bail!(
            "invalid GLB: its header declares {length} bytes; a GLB holds at least 20 and this file has {}",
            bytes.len()
        ),
        (Some(version), Some(_)) => bail!("invalid GLB: version {version}, only 2 is read"),
        _ => bail!("invalid GLB: the file ends inside its 12-byte header"),
    }
}

/// The glTF document if it passes the gltf crate's validation, whose errors are listed
/// (the first three) on one line. Attribute accessors are checked first: the crate's own
/// check of POSITION indexes the accessors unchecked and panics (found by a test).
pub(crate) fn validated(json: gltf::json::Root) -> Result<gltf::Document> {
    for (m, mesh) in json.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            for accessor in primitive.attributes.values() {
                if accessor.value() >= json.accessors.len() {
                    bail!(
                        "invalid glTF: meshes[{m}].primitives[{p}].attributes: accessor {} does not exist (the file has {})",
                        accessor.value(),
                        json.accessors.len()
                    );
                }
            }
        }
    }
    gltf::Document::from_json(json).map_err(|e| match e {
        gltf::Error::Validation(errors) => {
            let mut listed: Vec<String> = errors
                .iter()
                .take(3)
                .map(|(path, error)| format!("{path}: {error}"))
                .collect();
            if errors.len() > 3 {
                listed.push(format!("and {} more", errors.len() - 3));
            }
            anyhow!("invalid glTF: {}", listed.join("; "))
        }
        other => anyhow!("invalid glTF: {other}"),
    })
}

/// The first line of an OBJ that is broken, and why, checked before tobj reads the file:
/// tobj's errors name no line, it reads a face index 0 as "no index" without a word, and an
/// index far out of range overflows its arithmetic (a panic where overflow checks are on,
/// found by fuzzing). Vertex lines need three numbers (texture coordinates two); face, line
/// and point indices must be integers other than 0 that point at an element of the file
/// (negative ones count back from the line). `None` where no line is at fault by these rules.
/// Two passes over the bytes, nothing kept but counts.
pub(crate) fn obj_error_line(obj: &[u8]) -> Option<String> {
    let lines = || obj.split(|&b| b == b'\n').map(String::from_utf8_lossy);
    let mut totals = [0usize; 3];
    for line in lines() {
        match line.split_whitespace().next() {
            Some("v") => totals[0] += 1,
            Some("vt") => totals[1] += 1,
            Some("vn") => totals[2] += 1,
            _ => {}
        }
    }
    let mut so_far = [0usize; 3];
    for (i, line) in lines().enumerate() {
        let mut words = line.split_whitespace();
        let at = |why: String| Some(format!("line {}: {why}", i + 1));
        match words.next() {
            Some(key @ ("v" | "vt" | "vn")) => {
                let (slot, needed) = match key {
                    "v" => (0, 3),
                    "vt" => (1, 2),
                    _ => (2, 3),
                };
                so_far[slot] += 1;
                let numbers: Vec<&str> = words.take(needed).collect();
                if numbers.len() < needed || numbers.iter().any(|w| w.parse::<f32>().is_err()) {
                    return at(format!(
                        "`{key}` needs {needed} numbers, got `{}`",
                        clipped(&numbers.join(" "))
                    ));
                }
            }
            Some(key @ ("f" | "l" | "p")) => {
                for corner in words {
                    for (slot, part) in corner.split('/').enumerate().filter(|(_, p)| !p.is_empty())
                    {
                        let kind = ["vertex", "texture coordinate", "normal"].get(slot);
                        let ok = match (kind, part.parse::<isize>()) {
                            (Some(_), Ok(x)) if x > 0 => x as usize <= totals[slot],
                            (Some(_), Ok(x)) if x < 0 => x.unsigned_abs() <= so_far[slot],
                            _ => false,
                        };
                        if !ok {
                            return at(format!(
                                "`{key}` corner `{}`: `{}` is not the index of a {} (the file has {})",
                                clipped(corner),
                                clipped(part),
                                kind.unwrap_or(&"vertex"),
                                totals.get(slot).copied().unwrap_or(0)
                            ));
                        }
                    }
                }
            }
            _ => {}
        }
    }
    None
}
