//! What the mesh crates (tobj, gltf) do not check themselves, checked before they read a file:
//! where they would panic (found by tests and fuzzing) or accept without a word what cannot be
//! meant. Each error is one line naming the line, node or accessor.

use anyhow::{Result, anyhow, bail};

use crate::util::number::{short, short_list};

/// Text from a file for a message: at most 40 characters, control characters escaped.
pub(crate) fn clipped(text: &str) -> String {
    let mut out: String = text.chars().take(40).flat_map(char::escape_debug).collect();
    if text.chars().count() > 40 {
        out.push('…');
    }
    out
}

/// An index token for a message: at most 12 characters (`18446744073709551616` is cut).
fn clipped_token(text: &str) -> String {
    if text.chars().count() > 12 {
        let head: String = text.chars().take(12).flat_map(char::escape_debug).collect();
        format!("{head}…({} characters)", text.chars().count())
    } else {
        clipped(text)
    }
}

/// The first line of `bytes` that is not text tobj can read, and why: a NUL byte (a binary
/// file), bytes that are not UTF-8 (tobj's "read error", with no line), or a CR that ends a
/// line without LF (tobj reads a CR-only file as one line: "color parse error").
fn text_error(bytes: &[u8], kind: &str) -> Option<String> {
    for (i, line) in bytes.split(|&b| b == b'\n').enumerate() {
        let at = |why: String| Some(format!("line {}: {why}", i + 1));
        if line.contains(&0) {
            return at(format!("a NUL byte: not a text {kind}"));
        }
        if let Err(e) = std::str::from_utf8(line) {
            return at(format!(
                "byte {} of the line is not UTF-8 text: not a text {kind}",
                e.valid_up_to() + 1
            ));
        }
        if line
            .iter()
            .position(|&b| b == b'\r')
            .is_some_and(|at| at + 1 < line.len())
        {
            return at(format!(
                "a CR byte inside the line: the file uses CR line ends (classic Mac OS); save the {kind} with LF or CRLF line ends"
            ));
        }
    }
    None
}

/// The numbers of `words`, each finite; the error names the first word that is not.
fn finite_numbers(words: &[&str]) -> std::result::Result<Vec<f32>, String> {
    words
        .iter()
        .map(|w| match w.parse::<f32>() {
            Ok(x) if x.is_finite() => Ok(x),
            Ok(x) => Err(format!("{} is not finite", short(f64::from(x)))),
            Err(_) => Err(format!("`{}` is not a number", clipped(w))),
        })
        .collect()
}

/// What tobj does not check in an MTL file: text that is not (NUL bytes, not UTF-8, CR line
/// ends), colour lines without exactly three numbers (tobj unwraps fewer and panics, ignores
/// more), `Kd` outside [0, 1], a material name defined twice or missing, a value missing
/// after `Ns`, `map_Kd` and the like ("material parse error"). Errors give the line.
pub(crate) fn check_mtl_lines(mtl: &[u8]) -> std::result::Result<(), String> {
    if let Some(why) = text_error(mtl, "MTL") {
        return Err(why);
    }
    let mut defined = std::collections::HashMap::new();
    let mut current = String::new();
    for (i, line) in mtl.split(|&b| b == b'\n').enumerate() {
        let line = String::from_utf8_lossy(line);
        let at = |why: String| Err(format!("line {}: {why}", i + 1));
        let mut words = line.split_whitespace();
        let key = words.next();
        let rest: Vec<&str> = words.collect();
        match key {
            Some(key @ ("Ka" | "Kd" | "Ks" | "Ke")) => {
                if rest.len() != 3 || rest.iter().any(|w| w.parse::<f32>().is_err()) {
                    return at(format!(
                        "`{key}` needs three numbers, got `{}`",
                        clipped(&rest.join(" "))
                    ));
                }
                let c: Vec<f64> = rest
                    .iter()
                    .map(|w| f64::from(w.parse::<f32>().unwrap_or(0.0)))
                    .collect();
                if key == "Kd" && c.iter().any(|c| !(0.0..=1.0).contains(c)) {
                    return at(format!(
                        "material `{}` has the colour `Kd` {}: components must be in [0, 1]",
                        clipped(&current),
                        short_list(&c)
                    ));
                }
            }
            Some(key @ ("Ns" | "Ni" | "d" | "Tr"))
                if rest.len() != 1 || rest[0].parse::<f32>().is_err() =>
            {
                return at(format!(
                    "`{key}` needs one number, got `{}`",
                    clipped(&rest.join(" "))
                ));
            }
            Some("illum") if rest.len() != 1 || rest[0].parse::<u8>().is_err() => {
                return at(format!(
                    "`illum` needs one integer in [0, 255], got `{}`",
                    clipped(&rest.join(" "))
                ));
            }
            Some(
                key @ ("map_Ka" | "map_Kd" | "map_Ks" | "map_Bump" | "map_bump" | "map_Ns"
                | "map_ns" | "map_NS" | "bump" | "map_d"),
            ) if rest.is_empty() => {
                return at(format!("`{key}` needs a texture file name"));
            }
            Some("newmtl") => {
                let name = line.trim().split_once(' ').unwrap_or_default().1.trim();
                if name.is_empty() {
                    return at("`newmtl` needs a material name".into());
                }
                if let Some(first) = defined.insert(name.to_string(), i + 1) {
                    return at(format!(
                        "material `{}` is defined twice (first at line {first})",
                        clipped(name)
                    ));
                }
                current = name.to_string();
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
        (Some(2), Some(length)) if (12 + 8..=bytes.len()).contains(&length) => {
            check_glb_chunks(&bytes[..length])
        }
        (Some(2), Some(length)) => bail!(
            "invalid GLB: its header declares {length} bytes; a GLB holds at least 20 and this file has {}",
            bytes.len()
        ),
        (Some(version), Some(_)) => bail!("invalid GLB: version {version}, only 2 is read"),
        _ => bail!("invalid GLB: the file ends inside its 12-byte header"),
    }
}

/// A GLB's chunks (after its 12-byte header) must be a JSON chunk, not empty and a multiple
/// of 4 bytes long, then at most one BIN chunk, each inside the length the header declares:
/// the gltf crate says "JSON chunk length exceeds that of slice" or "unknown chunk type".
fn check_glb_chunks(glb: &[u8]) -> Result<()> {
    let word = |at: usize| {
        glb.get(at..at + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize)
    };
    let mut at = 12;
    for (n, (kind, name)) in [(0x4E4F_534A, "JSON"), (0x004E_4942, "BIN")]
        .into_iter()
        .enumerate()
    {
        if n == 1 && at == glb.len() {
            return Ok(()); // no BIN chunk
        }
        let (Some(length), Some(found)) = (word(at), word(at + 4)) else {
            bail!(
                "invalid GLB: the {name} chunk's 8-byte header at byte {at} does not fit the {} bytes the GLB header declares",
                glb.len()
            );
        };
        if found != kind {
            bail!(
                "invalid GLB: chunk {n} at byte {at} has the type {:?}; expected {name}",
                String::from_utf8_lossy(&glb[at + 4..at + 8])
            );
        }
        let room = glb.len() - at - 8;
        if length > room {
            bail!(
                "invalid GLB: its {name} chunk declares {length} bytes, but {room} follow its header within the {} bytes the GLB header declares",
                glb.len()
            );
        }
        if n == 0 && (length == 0 || !length.is_multiple_of(4)) {
            bail!(
                "invalid GLB: its JSON chunk is {length} bytes long; it must be a non-zero multiple of 4 (padded with spaces)"
            );
        }
        at += 8 + length;
    }
    if at != glb.len() {
        bail!(
            "invalid GLB: {} bytes follow its BIN chunk within the {} bytes the GLB header declares",
            glb.len() - at,
            glb.len()
        );
    }
    Ok(())
}

/// Where the glTF JSON `path` (`nodes[0].children[1]`) leads in `root`, if anywhere.
fn json_at<'a>(root: &'a serde_json::Value, path: &str) -> Option<&'a serde_json::Value> {
    let mut value = root;
    for part in path.split('.') {
        let (name, indices) = part.split_once('[').map_or((part, ""), |(n, i)| (n, i));
        if !name.is_empty() {
            value = value.get(name)?;
        }
        for index in indices.split('[').filter(|i| !i.is_empty()) {
            let index = index.trim_end_matches(']');
            value = match index.parse::<usize>() {
                Ok(i) => value.get(i)?,
                Err(_) => value.get(index.trim_matches('"'))?,
            };
        }
    }
    Some(value)
}

/// The top-level array an index at `path` points into (`nodes[0].children[1]`: `nodes`).
fn indexed_array(path: &str) -> Option<&'static str> {
    let field = path.rsplit('.').next()?;
    let field = field.split('[').next()?;
    Some(match field {
        "children" | "nodes" | "node" | "joints" | "skeleton" => "nodes",
        "mesh" => "meshes",
        "material" => "materials",
        "indices"
        | "attributes"
        | "accessor"
        | "inverseBindMatrices"
        | "input"
        | "output"
        | "targets" => "accessors",
        "bufferView" => "bufferViews",
        "buffer" => "buffers",
        "scene" => "scenes",
        "camera" => "cameras",
        "skin" => "skins",
        "source" => "images",
        "sampler" => "samplers",
        "index" => "textures",
        _ => return None,
    })
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
    // For "Index out of bounds": the index and the count the crate does not give.
    let value = serde_json::to_value(&json).unwrap_or_default();
    gltf::Document::from_json(json).map_err(|e| match e {
        gltf::Error::Validation(errors) => {
            let mut listed: Vec<String> = errors
                .iter()
                .take(3)
                .map(|(path, error)| {
                    let path = path.to_string();
                    let index = json_at(&value, &path).and_then(serde_json::Value::as_u64);
                    match (error, index) {
                        (gltf::json::validation::Error::IndexOutOfBounds, Some(index)) => {
                            match indexed_array(&path) {
                                Some(array) => format!(
                                    "{path}: index {index} is out of bounds: the file has {} {array}, [0, {}]",
                                    value[array].as_array().map_or(0, Vec::len),
                                    value[array].as_array().map_or(0, Vec::len) as i64 - 1
                                ),
                                None => format!("{path}: index {index} is out of bounds"),
                            }
                        }
                        _ => format!("{path}: {error}"),
                    }
                })
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
/// found by fuzzing). The file must be text (no NUL byte, UTF-8, LF or CRLF line ends).
/// Vertex lines need three finite numbers (texture coordinates two), then for `v` nothing,
/// a non-zero w or a colour of three, on every vertex or none; faces need three corners or
/// more, lines two; face, line and point indices must be integers other than 0 that point at
/// an element of the file (negative ones count back from the line); `usemtl` needs a name.
/// `None` where no line is at fault by these rules. Two passes over the bytes, nothing kept
/// but counts.
pub(crate) fn obj_error_line(obj: &[u8]) -> Option<String> {
    if let Some(why) = text_error(obj, "OBJ") {
        return Some(why);
    }
    // Text by the check above: each line UTF-8, so the whole.
    let text = std::str::from_utf8(obj).ok()?;
    let lines = || text.split('\n');
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
    // The first vertex line with a colour and the first without, if any.
    let mut coloured: [Option<usize>; 2] = [None, None];
    // One buffer for every line's words after the key.
    let mut rest: Vec<&str> = Vec::new();
    for (i, line) in lines().enumerate() {
        let mut words = line.split_whitespace();
        let at = |why: String| Some(format!("line {}: {why}", i + 1));
        let key = words.next();
        rest.clear();
        rest.extend(words);
        match key {
            Some(key @ ("v" | "vt" | "vn")) => {
                let (slot, needed, what) = match key {
                    "v" => (
                        0,
                        3,
                        "coordinates must be finite and within the world, [-1e6, 1e6] m",
                    ),
                    "vt" => (1, 2, "texture coordinates must be finite"),
                    _ => (2, 3, "normals must be finite"),
                };
                so_far[slot] += 1;
                let numbers = &rest[..needed.min(rest.len())];
                let parsed = || numbers.iter().map(|w| w.parse::<f32>());
                // Each number parsed once where all is well; the messages parse them again.
                if numbers.len() < needed || !parsed().all(|x| x.is_ok_and(f32::is_finite)) {
                    if numbers.len() < needed || parsed().any(|x| x.is_err()) {
                        return at(format!(
                            "`{key}` needs {needed} numbers, got `{}`",
                            clipped(&numbers.join(" "))
                        ));
                    }
                    if let Err(why) = finite_numbers(numbers) {
                        return at(format!(
                            "`{key}` {}: {why}: {what}",
                            clipped(&numbers.join(" "))
                        ));
                    }
                }
                if key != "v" {
                    continue;
                }
                let extra = &rest[3..];
                match finite_numbers(extra) {
                    Err(why) => {
                        return at(format!(
                            "`v` {}: {why}: after x y z come a weight w or a colour r g b, finite numbers",
                            clipped(&rest.join(" "))
                        ));
                    }
                    Ok(w) if w == [0.0] => {
                        return at("`v` has the weight w = 0: it must be a non-zero number".into());
                    }
                    Ok(_) if extra.len() == 2 || extra.len() > 3 => {
                        return at(format!(
                            "`v` has {} numbers: give 3 (x y z), 4 (and a weight w) or 6 (and a colour r g b)",
                            rest.len()
                        ));
                    }
                    Ok(_) => {}
                }
                let slot = usize::from(extra.len() != 3);
                coloured[slot].get_or_insert(i + 1);
                if let [Some(with), Some(without)] = coloured {
                    return at(format!(
                        "vertex colours are given on some vertices only (line {with} has one, line {without} none): give them on every vertex or none"
                    ));
                }
            }
            Some(key @ ("f" | "l" | "p")) => {
                let needed = match key {
                    "f" => 3,
                    "l" => 2,
                    _ => 1,
                };
                if rest.len() < needed {
                    let shape = match key {
                        "f" => "a face needs 3 corners or more",
                        "l" => "a line needs 2 points or more",
                        _ => "a point needs a vertex",
                    };
                    return at(format!(
                        "`{key}` has {} {}: {shape}",
                        rest.len(),
                        if rest.len() == 1 { "index" } else { "indices" }
                    ));
                }
                for &corner in &rest {
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
                                clipped_token(corner),
                                clipped_token(part),
                                kind.unwrap_or(&"vertex"),
                                totals.get(slot).copied().unwrap_or(0)
                            ));
                        }
                    }
                }
            }
            Some("usemtl") if rest.is_empty() => {
                return at("`usemtl` needs a material name".into());
            }
            _ => {}
        }
    }
    None
}
