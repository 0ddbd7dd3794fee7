//! Plane-to-plane projective maps (homographies) from four point correspondences.

use glam::{DMat3, DVec2};

/// The homography taking four points `from` to four points `to` (no three collinear).
pub fn homography(from: [DVec2; 4], to: [DVec2; 4]) -> DMat3 {
    // Direct linear transform with h33 = 1: eight equations in eight unknowns.
    let mut a = [[0.0f64; 9]; 8];
    for i in 0..4 {
        let (x, y, u, v) = (from[i].x, from[i].y, to[i].x, to[i].y);
        a[2 * i] = [x, y, 1.0, 0.0, 0.0, 0.0, -u * x, -u * y, u];
        a[2 * i + 1] = [0.0, 0.0, 0.0, x, y, 1.0, -v * x, -v * y, v];
    }
    let h = solve8(a);
    DMat3::from_cols_array(&[h[0], h[3], h[6], h[1], h[4], h[7], h[2], h[5], 1.0])
}

/// Gaussian elimination with partial pivoting on an 8×8 system in augmented form.
fn solve8(mut a: [[f64; 9]; 8]) -> [f64; 8] {
    for col in 0..8 {
        let pivot = (col..8)
            .max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))
            .unwrap_or(col);
        a.swap(col, pivot);
        let pivot_row = a[col];
        for row in a.iter_mut().skip(col + 1) {
            let f = row[col] / pivot_row[col];
            for (x, p) in row.iter_mut().zip(pivot_row).skip(col) {
                *x -= f * p;
            }
        }
    }
    let mut x = [0.0; 8];
    for row in (0..8).rev() {
        let sum: f64 = (row + 1..8).map(|k| a[row][k] * x[k]).sum();
        x[row] = (a[row][8] - sum) / a[row][row];
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn homography_maps_the_four_points_and_lines_to_lines() {
        let from = [
            DVec2::new(0.0, 0.0),
            DVec2::new(4.0, 0.0),
            DVec2::new(4.0, 3.0),
            DVec2::new(0.0, 3.0),
        ];
        let to = [
            DVec2::new(10.0, 5.0),
            DVec2::new(30.0, 7.0),
            DVec2::new(28.0, 25.0),
            DVec2::new(12.0, 20.0),
        ];
        let m = homography(from, to);
        let map = |p: DVec2| {
            let q = m * p.extend(1.0);
            DVec2::new(q.x / q.z, q.y / q.z)
        };
        for (f, t) in from.iter().zip(&to) {
            assert!((map(*f) - *t).length() < 1e-9);
        }
        // The midpoint of an edge maps onto the image edge (collinearity is preserved).
        let mid = map(DVec2::new(2.0, 0.0));
        let cross = (to[1] - to[0]).perp_dot(mid - to[0]);
        assert!(cross.abs() < 1e-9);
    }
}
