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
    pub metrics: crate::measure::metrics_json::Metrics,
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

/// How wide an embedded image is shown: views side by side, maps and figures full width (a
/// reader must be able to read their scales).
#[derive(Clone, Copy)]
enum Width {
    Half,
    Full,
}

fn img_tag(html: bool, dir: &Path, rel: &str, width: Width) -> Result<String> {
    use base64::Engine as _;
    if !html {
        return Ok(format!("![{rel}]({rel})"));
    }
    let bytes = std::fs::read(dir.join(rel)).with_context(|| format!("cannot read {rel}"))?;
    let mime = if rel.ends_with(".svg") {
        "image/svg+xml"
    } else {
        "image/png"
    };
    let style = match width {
        Width::Half => "width:49%",
        Width::Full => "width:100%;max-width:1200px",
    };
    Ok(format!(
        "<img src=\"data:{mime};base64,{}\" alt=\"{rel}\" style=\"{style}\">",
        base64::engine::general_purpose::STANDARD.encode(bytes)
    ))
}

/// A statistic to two decimals; "—" for none (NaN, or an infinite PSNR: JSON's null).
fn num(x: f64) -> String {
    match !x.is_finite() {
        true => "—".into(),
        false => format!("{x:.2}"),
    }
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
        "| case | coverage | mean ′ | p95 ′ | max ′ | border mean ′ | border p95 ′ | PSNR dB | SSIM | truth unseen by the frontal camera |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|---|---|---|---|---|");
    for c in cases {
        let (d, b) = (&c.metrics.display, &c.metrics.border);
        let coverage = c.metrics.coverage;
        let _ = writeln!(
            md,
            "| {} | {:.1}%{} | {} | {} | {} | {} | {} | {} | {} | {:.1}% |",
            c.name,
            100.0 * coverage,
            if coverage < 1.0 { " †" } else { "" },
            num(d.misregistration_arcmin.mean),
            num(d.misregistration_arcmin.p95),
            num(d.misregistration_arcmin.max),
            num(b.misregistration_arcmin.mean),
            num(b.misregistration_arcmin.p95),
            num(d.psnr_db),
            num(d.ssim),
            100.0 * c.metrics.missing.fraction
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
        "\nPer case: truth and seethru side by side, then the misregistration heatmap (colour scale in arc-minutes, clipped at the 99th percentile of the display; magenta: no direction; black: blank).\n"
    );
    for c in cases {
        let _ = writeln!(md, "### {}\n", c.name);
        let crop = &c.run["crop"];
        let outside: Vec<String> = ["left", "right", "top", "bottom"]
            .iter()
            .filter_map(|side| {
                let px = crop["outside_frontal_view_px"][side].as_f64()?;
                (px > 0.0).then(|| format!("{side} by {px:.0} frontal px"))
            })
            .collect();
        let _ = writeln!(
            md,
            "R1 = {}, R2 = {}. {} Coverage of the display in the driver's view: {:.1}%; {:.1}% of the display image's own pixels are black.\n",
            num(crop["R1_left"].as_f64().unwrap_or(f64::NAN)),
            num(crop["R2_right"].as_f64().unwrap_or(f64::NAN)),
            if outside.is_empty() {
                "The crop lies inside the frontal view.".to_string()
            } else {
                format!(
                    "The crop leaves the frontal view on the {}.",
                    outside.join(", ")
                )
            },
            100.0 * c.metrics.coverage,
            100.0 * c.run["missing_fraction"].as_f64().unwrap_or(0.0),
        );
        for image in ["truth.png", "seethru.png"] {
            let tag = img_tag(html, out, &format!("{}/{image}", c.dir), Width::Half)?;
            let _ = write!(md, "{tag} ");
        }
        let heatmap = img_tag(
            html,
            out,
            &format!("{}/misregistration.png", c.dir),
            Width::Full,
        )?;
        let _ = writeln!(md, "\n\n{heatmap}\n");
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
            let tag = img_tag(html, out, &format!("{dir}/{image}"), Width::Half)?;
            let _ = write!(md, "{tag} ");
        }
        let _ = writeln!(md, "\n");
    }
    let _ = writeln!(md, "## The paper's figures (§5.1)\n");
    for f in figures {
        let figure = if html {
            format!("figures/{f}.svg")
        } else {
            format!("figures/{f}.png")
        };
        let _ = writeln!(md, "{}\n", img_tag(html, out, &figure, Width::Full)?);
    }
    let _ = writeln!(
        md,
        "## Notes\n\n- The occlusion and foreshortening ratios are measured from the renders' id and position buffers; the model plane is the scene plane (the paper's case), so the prediction is the closed form; the uncertainty is the pixel quantisation (the driver's pixels, and for p_cam the display's and the frontal camera's), and it shrinks with resolution. The paper's Unity measurements missed their predictions by 0.02 and 0.17.\n- With D = 1 m at d1 = 0.75 m, θ_F = 30° cannot cover the display's view: the part outside the frontal camera's view is black and counted as missing; compare it with 63.5° only at equal coverage (above).\n- See docs/reference/equations-errata.md in the seethru repository for the errata of the paper's formulas."
    );
    if !html {
        return Ok(md);
    }
    Ok(markdown_to_html(&md))
}

/// The Markdown as one self-contained HTML page (pulldown-cmark, with tables; the embedded
/// images pass through as inline HTML).
fn markdown_to_html(md: &str) -> String {
    use pulldown_cmark::{Options, Parser, html};
    let mut body = String::new();
    html::push_html(&mut body, Parser::new_ext(md, Options::ENABLE_TABLES));
    format!(
        "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>seethru report</title><style>body{{font-family:sans-serif;max-width:1250px;margin:2em auto;line-height:1.4}}table{{border-collapse:collapse}}td,th{{border:1px solid #ccc;padding:4px 8px;text-align:right}}td:first-child,th:first-child{{text-align:left}}img{{margin:2px 0}}</style></head><body>\n{body}</body></html>\n"
    )
}
