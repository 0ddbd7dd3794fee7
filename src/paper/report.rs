//! The reproduction's report: the cases, ratios and figures as Markdown, or as one
//! self-contained HTML page with the images embedded.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::{Context, Result};

use crate::measure::ratio::RatioResult;

/// Sizes of one reproduction.
pub struct Sizes {
    pub driver: u32,
    pub frontal: u32,
    pub ratio: u32,
    pub spp: u32,
}

pub struct CaseResult {
    pub name: String,
    pub dir: String,
    pub metrics: serde_json::Value,
    pub run: serde_json::Value,
}

/// Cases compared over the same display pixels: those that every one of them covers.
#[derive(Clone, Debug, serde::Serialize)]
pub struct EqualCoverage {
    pub label: String,
    /// Display pixels every case covers, and their fraction of the display.
    pub pixels: usize,
    pub coverage: f64,
    /// (case name, mean misregistration over those pixels in arc-minutes).
    pub means: Vec<(String, f64)>,
}

fn img_tag(html: bool, dir: &Path, rel: &str) -> Result<String> {
    if !html {
        return Ok(format!("![{rel}]({rel})"));
    }
    let bytes = std::fs::read(dir.join(rel)).with_context(|| format!("cannot read {rel}"))?;
    Ok(format!(
        "<img src=\"data:image/png;base64,{}\" alt=\"{rel}\" style=\"max-width:32%\">",
        base64(&bytes)
    ))
}

fn base64(bytes: &[u8]) -> String {
    const TABLE: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let n = (b[0] as u32) << 16 | (b[1] as u32) << 8 | b[2] as u32;
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(TABLE[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

fn num(v: &serde_json::Value) -> String {
    v.as_f64().map_or("—".into(), |x| format!("{x:.2}"))
}

pub fn render_report(
    out: &Path,
    cases: &[CaseResult],
    equal: &[EqualCoverage],
    ratios: &[(String, String, RatioResult)],
    figures: &[String],
    sizes: &Sizes,
    html: bool,
) -> Result<String> {
    let mut md = String::new();
    let _ = writeln!(md, "# seethru — reproduction of the paper's results (§5)\n");
    let _ = writeln!(
        md,
        "Borsoi & Costa, *On the Performance and Implementation of Parallax free Video See-Through Displays*. \
         Every number below comes from renders made for this report: driver view {} px wide, frontal camera {} px, \
         {} samples per pixel; ratio setups at {} px. Misregistration is the angle at the driver's eye between the \
         world point the display shows and the one the truth has there (1′ ≈ visual acuity).\n",
        sizes.driver, sizes.frontal, sizes.spp, sizes.ratio
    );
    let _ = writeln!(
        md,
        "## The das scene: the planar model with d2 → ∞ (paper Figs. 4 and 5)\n"
    );
    let _ = writeln!(
        md,
        "| case | coverage | mean ′ | p95 ′ | max ′ | border mean ′ | border p95 ′ | PSNR dB | SSIM | missing |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|---|---|---|---|---|");
    for c in cases {
        let d = &c.metrics["display"];
        let b = &c.metrics["border"];
        let coverage = c.metrics["coverage"].as_f64().unwrap_or(f64::NAN);
        let _ = writeln!(
            md,
            "| {} | {:.1}%{} | {} | {} | {} | {} | {} | {} | {} | {:.1}% |",
            c.name,
            100.0 * coverage,
            if coverage < 1.0 { " †" } else { "" },
            num(&d["misregistration_arcmin"]["mean"]),
            num(&d["misregistration_arcmin"]["p95"]),
            num(&d["misregistration_arcmin"]["max"]),
            num(&b["misregistration_arcmin"]["mean"]),
            num(&b["misregistration_arcmin"]["p95"]),
            num(&d["psnr_db"]),
            num(&d["ssim"]),
            100.0 * c.metrics["missing"]["fraction"].as_f64().unwrap_or(0.0)
        );
    }
    let _ = writeln!(
        md,
        "\nCoverage: the fraction of the display's pixels that show the scene. † Part of the display is black (the crop leaves the frontal view): its misregistration statistics are over the covered part only, so they are not comparable with a fully covered row; PSNR and SSIM count the black part as the black it shows.\n"
    );
    if !equal.is_empty() {
        let _ = writeln!(
            md,
            "At equal coverage — each car position's cases over the display pixels that all of them cover:\n"
        );
        let _ = writeln!(md, "| pixels compared | coverage | mean ′ per case |");
        let _ = writeln!(md, "|---|---|---|");
        for e in equal {
            let means: Vec<String> = e
                .means
                .iter()
                .map(|(name, m)| format!("{name}: {m:.2}"))
                .collect();
            let _ = writeln!(
                md,
                "| {}: {} | {:.1}% | {} |",
                e.label,
                e.pixels,
                100.0 * e.coverage,
                means.join("; ")
            );
        }
    }
    let _ = writeln!(
        md,
        "\nLeft to right: truth, seethru, misregistration heatmap.\n"
    );
    for c in cases {
        let _ = writeln!(md, "### {}\n", c.name);
        let crop = &c.run["crop"];
        let _ = writeln!(
            md,
            "R1 = {}, R2 = {}, missing {:.1}% of the display (crop outside the frontal view: {}).\n",
            num(&crop["R1_left"]),
            num(&crop["R2_right"]),
            100.0 * c.run["missing_fraction"].as_f64().unwrap_or(0.0),
            crop["outside_frontal_view_px"]
        );
        for image in ["truth.png", "seethru.png", "misregistration.png"] {
            let _ = write!(
                md,
                "{} ",
                img_tag(html, out, &format!("{}/{image}", c.dir))?
            );
        }
        let _ = writeln!(md, "\n");
    }
    let _ = writeln!(
        md,
        "## Occlusion and foreshortening: p_cam/p_user (paper Figs. 6 and 7)\n"
    );
    let _ = writeln!(
        md,
        "| case | predicted (closed form) | observed (seethru) | uncertainty | paper predicted | paper measured (Unity) |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|---|");
    for (name, _, r) in ratios {
        let opt = |v: Option<f64>| v.map_or("—".into(), |x| format!("{x:.2}"));
        let _ = writeln!(
            md,
            "| {name} | {:.4} | {:.4} | ±{:.4} | {} | {} |",
            r.ratio.predicted,
            r.ratio.observed,
            r.ratio.uncertainty,
            opt(r.paper_printed),
            opt(r.paper_unity)
        );
    }
    let _ = writeln!(
        md,
        "\nWidths on the scene plane (m), where the driver perceives the edges (along the line of sight through each display pixel):\n"
    );
    let _ = writeln!(
        md,
        "| case | p_cam predicted | p_cam observed | p_user predicted | p_user observed |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|");
    for (name, _, r) in ratios {
        let _ = writeln!(
            md,
            "| {name} | {:.4} | {:.4} ± {:.4} | {:.4} | {:.4} ± {:.4} |",
            r.p_cam.predicted,
            r.p_cam.observed,
            r.p_cam.uncertainty,
            r.p_user.predicted,
            r.p_user.observed,
            r.p_user.uncertainty
        );
    }
    let _ = writeln!(md);
    for (name, dir, _) in ratios {
        let _ = writeln!(md, "### {name}\n\nTruth, then seethru.\n");
        for image in ["truth.png", "seethru.png"] {
            let _ = write!(md, "{} ", img_tag(html, out, &format!("{dir}/{image}"))?);
        }
        let _ = writeln!(md, "\n");
    }
    let _ = writeln!(md, "## The paper's figures (§5.1)\n");
    for f in figures {
        let _ = writeln!(md, "{}\n", img_tag(html, out, &format!("figures/{f}.png"))?);
    }
    let _ = writeln!(
        md,
        "## Notes\n\n- The occlusion and foreshortening ratios are measured from the renders' id and position buffers; the model plane is the scene plane (the paper's case), so the prediction is the closed form; the uncertainty is the pixel quantisation (the driver's pixels, and for p_cam the display's and the frontal camera's), and it shrinks with resolution. The paper's Unity measurements missed their predictions by 0.02 and 0.17.\n- With D = 1 m at d1 = 0.75 m, θ_F = 30° cannot cover the display's view: the part outside the frontal camera's view is black and counted as missing; compare it with 63.5° only at equal coverage (above).\n- See the README for the errata of the paper's formulas."
    );
    if !html {
        return Ok(md);
    }
    Ok(markdown_to_html(&md))
}

/// A minimal Markdown subset (headings, tables, paragraphs, list items; inline HTML passes
/// through) to self-contained HTML.
fn markdown_to_html(md: &str) -> String {
    let mut html = String::from(
        "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>seethru report</title><style>body{font-family:sans-serif;max-width:1400px;margin:2em auto;line-height:1.4}table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:4px 8px;text-align:right}td:first-child{text-align:left}img{margin:2px}</style></head><body>\n",
    );
    let escape = |s: &str| {
        if s.trim_start().starts_with("<img") {
            s.to_string()
        } else {
            s.replace('&', "&amp;")
                .replace('<', "&lt;")
                .replace('>', "&gt;")
                .replace('*', "")
        }
    };
    let mut in_table = false;
    for line in md.lines() {
        if line.starts_with('|') {
            if line.contains("|---") {
                continue;
            }
            if !in_table {
                html += "<table>\n";
                in_table = true;
            }
            let cells: Vec<&str> = line.trim_matches('|').split('|').map(str::trim).collect();
            html += &format!(
                "<tr>{}</tr>\n",
                cells
                    .iter()
                    .map(|c| format!("<td>{}</td>", escape(c)))
                    .collect::<String>()
            );
            continue;
        }
        if in_table {
            html += "</table>\n";
            in_table = false;
        }
        if let Some(h) = line.strip_prefix("### ") {
            html += &format!("<h3>{}</h3>\n", escape(h));
        } else if let Some(h) = line.strip_prefix("## ") {
            html += &format!("<h2>{}</h2>\n", escape(h));
        } else if let Some(h) = line.strip_prefix("# ") {
            html += &format!("<h1>{}</h1>\n", escape(h));
        } else if let Some(item) = line.strip_prefix("- ") {
            html += &format!("<p>• {}</p>\n", escape(item));
        } else if line.contains("<img") {
            html += &format!("<p>{line}</p>\n");
        } else if !line.trim().is_empty() {
            html += &format!("<p>{}</p>\n", escape(line));
        }
    }
    if in_table {
        html += "</table>\n";
    }
    html + "</body></html>\n"
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_matches_the_rfc_examples() {
        for (input, expected) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(base64(input.as_bytes()), expected);
        }
    }

    #[test]
    fn tables_and_headings_become_html() {
        let html = markdown_to_html("# T\n\n| a | b |\n|---|---|\n| 1 | <2 |\n\n- item");
        assert!(
            html.contains("<h1>T</h1>")
                && html.contains("<td>&lt;2</td>")
                && html.contains("• item")
        );
    }
}
