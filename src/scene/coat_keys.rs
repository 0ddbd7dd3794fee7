//! A glossy coat's keys, read alike by `[[material]]` and `[road]`: `specular` (the coat's
//! reflectance at normal incidence F0, [0, 1], default 0: none) and `roughness` (its GGX α,
//! [`MIN_ROUGHNESS`], 1], default [`DEFAULT_ROUGHNESS`]).

use crate::scene::limits::{DEFAULT_ROUGHNESS, MIN_ROUGHNESS};
use crate::scene::source::SceneError;
use crate::scene::table_reader::TableReader;

/// The coat of table `t`, (F0, α); a roughness without a coat to shape is refused.
pub fn read_coat(t: &TableReader) -> Result<(f64, f64), SceneError> {
    let specular = t.f64_in("specular", 0.0, 0.0, 1.0)?;
    let roughness = t.f64_in("roughness", DEFAULT_ROUGHNESS, MIN_ROUGHNESS, 1.0)?;
    if t.has("roughness") && specular == 0.0 {
        return Err(t.error(
            "roughness",
            "shapes the glossy coat, and there is none: give specular in (0, 1] too",
        ));
    }
    Ok((specular, roughness))
}
