//! A recorded head path for `seethru sequence --head-path`: a CSV of `t,x,y,z` rows — time in
//! seconds, the eye in the obstacle frame in metres — read with the `csv` crate. Times must
//! increase; every value must be a finite number; a first line of names (`t,x,y,z`) is a
//! header, and `#` starts a comment.

use std::path::Path;

use anyhow::{Result, bail};
use glam::DVec3;

use crate::util::number_rows::number_rows;

/// Most rows of a head path.
pub const MAX_ROWS: usize = 1_000_000;

/// The eye's path in the obstacle frame: linear between samples, held outside them.
#[derive(Clone, Debug, PartialEq)]
pub struct HeadPath {
    /// (time s, eye in the obstacle frame m), times strictly increasing.
    pub samples: Vec<(f64, DVec3)>,
    /// The file's name for messages, and each sample's line in it.
    pub name: String,
    pub lines: Vec<u64>,
}

/// Largest head-path CSV read (a million samples of four numbers fit).
pub const MAX_HEAD_PATH_BYTES: u64 = 64 << 20;

impl HeadPath {
    pub fn load(path: &Path) -> Result<HeadPath> {
        let text = crate::util::input_file::read_input(path, MAX_HEAD_PATH_BYTES)
            .map_err(|e| anyhow::anyhow!("{}: cannot read the head path: {e}", path.display()))?;
        Self::parse(&text, &path.display().to_string())
    }

    /// Parses CSV `text`; errors name `name` and the line.
    pub fn parse(text: &[u8], name: &str) -> Result<HeadPath> {
        let rows = number_rows(
            text,
            name,
            ["t", "x", "y", "z"],
            "seconds, metres in the obstacle frame",
            MAX_ROWS,
        )?;
        let mut samples: Vec<(f64, DVec3)> = Vec::new();
        let mut lines = Vec::new();
        for (line, [t, x, y, z]) in rows {
            if let Some(&(previous, _)) = samples.last()
                && t <= previous
            {
                bail!("{name}:{line}: times must increase: t = {t} s follows t = {previous} s");
            }
            samples.push((t, DVec3::new(x, y, z)));
            lines.push(line);
        }
        if samples.is_empty() {
            bail!("{name}: the head path has no rows (expected t,x,y,z lines)");
        }
        Ok(HeadPath {
            samples,
            name: name.to_string(),
            lines,
        })
    }

    /// Refuses a path that puts the eye outside the world (the camera limit that
    /// `camera.driver.position` obeys) once placed by `world_from_obstacle`; the error names
    /// the file and the line.
    pub fn check_in_world(&self, world_from_obstacle: &glam::DAffine3) -> Result<()> {
        for (&(t, eye), line) in self.samples.iter().zip(&self.lines) {
            let world = world_from_obstacle.transform_point3(eye);
            if let Some(why) = crate::scene::limits::out_of_world(world) {
                bail!(
                    "{}:{line}: the eye at t = {t} s lies outside the world once placed by the obstacle: {why}",
                    self.name
                );
            }
        }
        Ok(())
    }

    /// The eye at time `t`, obstacle frame.
    pub fn at(&self, t: f64) -> DVec3 {
        let s = &self.samples;
        match s.iter().position(|&(ts, _)| ts > t) {
            Some(0) => s[0].1,
            None => s[s.len() - 1].1,
            Some(i) => {
                let ((t0, a), (t1, b)) = (s[i - 1], s[i]);
                a.lerp(b, (t - t0) / (t1 - t0))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_path_reads_interpolates_and_holds() {
        let p = HeadPath::parse(b"t,x,y,z\n0,0,0,0.7\n1, 0.1, 0, 0.7\n", "p.csv").unwrap();
        assert_eq!(p.samples.len(), 2);
        assert!((p.at(0.5).x - 0.05).abs() < 1e-15);
        assert_eq!((p.at(-1.0).x, p.at(5.0).x), (0.0, 0.1));
    }

    #[test]
    fn bad_paths_name_the_line() {
        let err = |text: &str| {
            HeadPath::parse(text.as_bytes(), "p.csv")
                .unwrap_err()
                .to_string()
        };
        assert!(err("0,0,0,1\n0,0,0,1\n").starts_with("p.csv:2: times must increase"));
        assert!(err("0,0,0,1\n1,NaN,0,1\n").starts_with("p.csv:2: `x` must be a finite"));
        assert!(err("0,0,0\n").starts_with("p.csv:1: expected 4 values"));
        assert!(err("").contains("no rows"));
    }
}
