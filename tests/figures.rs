//! The figures' data (CSV) carry the paper's numbers; the PNGs are real plots.

use seethru::paper::figures::write_all;

fn read_csv(path: &std::path::Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    (header, rows)
}

#[test]
fn figures_and_their_data() {
    let dir = tempfile::tempdir().unwrap();
    let names = write_all(dir.path()).unwrap();
    assert_eq!(names.len(), 4);
    for name in &names {
        let png = image::open(dir.path().join(format!("{name}.png")))
            .unwrap()
            .to_rgb8();
        // A plot, not a blank canvas: many coloured (non-grey) pixels.
        let coloured = png
            .pixels()
            .filter(|p| p[0].abs_diff(p[1]) > 60 || p[1].abs_diff(p[2]) > 60)
            .count();
        assert!(coloured > 2000, "{name}: {coloured} coloured pixels");
    }

    // Fig. 3: θ_F = 80° reaches 0.95·R1(∞) at d2 ≈ 0.90 m (the paper: "for all d2 > 0.9").
    let (header, rows) = read_csv(&dir.path().join("fig3_cutting_ratio.csv"));
    let curve = header
        .iter()
        .position(|h| h.starts_with("θ_F = 80°"))
        .unwrap();
    let bound = header
        .iter()
        .position(|h| h.starts_with("0.95·R1(∞) at θ_F = 80°"))
        .unwrap();
    let first = rows.iter().find(|r| r[curve] >= r[bound]).unwrap()[0];
    assert!((first - 0.91).abs() < 0.006, "admissible from {first}");
    // Larger θ_F converges faster: at d2 = 1 m the ratio R1/R1(∞) grows with θ_F.
    let at1 = rows.iter().find(|r| (r[0] - 1.0).abs() < 1e-9).unwrap();
    let fractions: Vec<f64> = (1..header.len())
        .step_by(2)
        .map(|c| at1[c] / (at1[c + 1] / 0.95))
        .collect();
    assert!(fractions.windows(2).all(|w| w[0] < w[1]), "{fractions:?}");

    // Fig. 4: each occlusion curve falls towards b1 / (b1 + b_h) as d2 grows.
    let (header, rows) = read_csv(&dir.path().join("fig4_occlusion.csv"));
    for (c, h) in header.iter().enumerate().skip(1) {
        let b1: f64 = h
            .trim_start_matches("b1 = ")
            .trim_end_matches(" m")
            .parse()
            .unwrap();
        let column: Vec<f64> = rows.iter().map(|r| r[c]).collect();
        assert!(column.windows(2).all(|w| w[1] < w[0]), "{h} not decreasing");
        let limit = b1 / (b1 + 0.25);
        let (first, last) = (column[0], *column.last().unwrap());
        assert!(
            last > limit && last - limit < 0.1 * (first - limit),
            "{h}: {first} → {last}, limit {limit}"
        );
    }

    // Fig. 5: foreshortening ratios approach 1 far away.
    let (_, rows) = read_csv(&dir.path().join("fig5_foreshortening.csv"));
    assert!(
        rows.last().unwrap()[1..]
            .iter()
            .all(|v| (v - 1.0).abs() < 0.12)
    );
    assert!(rows[0][1..].iter().any(|v| (v - 1.0).abs() > 0.3));
}

#[test]
fn figures_are_also_svg_with_their_text_as_text() {
    // Sharp in a browser at any size, and searchable: the caption and axis labels are text
    // elements, each curve a path of its own.
    let dir = tempfile::tempdir().unwrap();
    for name in write_all(dir.path()).unwrap() {
        let svg = std::fs::read_to_string(dir.path().join(format!("{name}.svg"))).unwrap();
        let doc = roxmltree::Document::parse(&svg).unwrap();
        let root = doc.root_element();
        assert_eq!(root.tag_name().name(), "svg");
        assert!(root.attribute("width").unwrap().parse::<u32>().unwrap() >= 800);
        let texts: Vec<String> = doc
            .descendants()
            .filter(|n| n.has_tag_name("text"))
            .map(|n| n.text().unwrap_or_default().trim().to_string())
            .collect();
        // The curves' legends (dashed companion curves have none: at least half are named).
        let (header, _) = read_csv(&dir.path().join(format!("{name}.csv")));
        let series = &header[1..];
        // (The CSV writes a label's commas as semicolons.)
        let named = series
            .iter()
            .filter(|l| texts.iter().any(|t| t.replace(',', ";") == **l))
            .count();
        assert!(
            2 * named >= series.len() && named > 0,
            "{name}: {named} of {series:?} among {texts:?}"
        );
    }
}
