//! XYZ point lists: one point per line, `x y z`, on a regular grid (`NaN` in z = missing point).
//!
//! The grid is inferred from the coordinates: the distinct x (and y) values must be equally
//! spaced, and the points must fill the grid they span, each node once. A scattered point set
//! is refused, never interpolated. The lines may come in any order; x runs along the columns,
//! y along the rows. The coordinates carry no unit, so the physical size is left to the user
//! (`--size`), as is the height unit.
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use ndarray::Array2;

use super::gwyddion_txt::GwyddionTxt;
use super::reading::{Channel, Format};
use super::text::{self, Separators};

pub struct Xyz;

/// Coordinates closer than this fraction of their range are the same grid line (exports round
/// them when they print them).
const SAME_LINE: f64 = 1e-6;
/// How far from its grid node a coordinate may lie, as a fraction of the grid step.
const OFF_NODE: f64 = 0.1;

impl Format for Xyz {
    fn name(&self) -> &'static str {
        "xyz"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["xyz"]
    }

    /// A table of exactly three numbers a line, without Gwyddion's header.
    fn sniff(&self, head: &[u8]) -> bool {
        text::table_head(head).is_some_and(|t| t.columns == 3 && t.complete) && !GwyddionTxt.sniff(head)
    }

    fn read(&self, bytes: &[u8]) -> Result<Vec<Channel>, String> {
        let text = text::decode(bytes)?;
        let (mut xs, mut ys, mut zs) = (Vec::new(), Vec::new(), Vec::new());
        let mut sep = None;
        let mut row = Vec::with_capacity(3);
        for (i, line) in text.lines().enumerate() {
            let line_no = i + 1;
            if line.trim().is_empty() || text::comment_body(line).is_some() {
                continue;
            }
            let s = match sep {
                Some(s) => s,
                None => match Separators::detect(line) {
                    Some(s) => *sep.insert(s),
                    None if text::key_value(line).is_some() => continue,
                    None => {
                        return Err(format!(
                            "no topography in it: line {line_no} ('{}') is not an x y z point",
                            text::excerpt(line)
                        ))
                    }
                },
            };
            row.clear();
            s.row(line, &mut row).map_err(|e| format!("line {line_no}: {e}"))?;
            let &[x, y, z] = row.as_slice() else {
                return Err(format!("line {line_no} holds {} values, not the 3 of an x y z point", row.len()));
            };
            if !(x.is_finite() && y.is_finite()) {
                return Err(format!("line {line_no}: the point has no x or y coordinate"));
            }
            xs.push(x);
            ys.push(y);
            zs.push(z);
        }
        if zs.is_empty() {
            return Err("no topography in it: no x y z point".into());
        }
        let gx = Axis::infer(&xs, "x")?;
        let gy = Axis::infer(&ys, "y")?;
        let nodes = gx.n.checked_mul(gy.n).filter(|&n| n == zs.len()).ok_or_else(|| {
            format!(
                "the {} points do not fill a regular grid: their coordinates span {} × {} nodes",
                zs.len(),
                gx.n,
                gy.n
            )
        })?;
        let mut data = Array2::from_elem((gy.n, gx.n), f64::NAN);
        let mut filled = vec![false; nodes];
        for ((&x, &y), &z) in xs.iter().zip(&ys).zip(&zs) {
            let (ix, iy) = (gx.node(x), gy.node(y));
            let k = iy * gx.n + ix;
            if std::mem::replace(&mut filled[k], true) {
                return Err(format!("two points lie on the grid node x = {x}, y = {y}"));
            }
            data[(iy, ix)] = z;
        }
        Ok(vec![Channel { name: "default".into(), data, physical_size: None, unit: None, is_height: true }])
    }
}

/// The equally spaced coordinates of one grid axis.
struct Axis {
    origin: f64,
    step: f64,
    n: usize,
}

impl Axis {
    fn infer(values: &[f64], name: &str) -> Result<Self, String> {
        let mut sorted = values.to_vec();
        sorted.sort_by(f64::total_cmp);
        let (lo, hi) = (sorted[0], sorted[sorted.len() - 1]);
        let tol = SAME_LINE * (hi - lo);
        let mut lines = vec![lo];
        for &v in &sorted {
            if v - lines[lines.len() - 1] > tol {
                lines.push(v);
            }
        }
        let n = lines.len();
        if n < 2 {
            return Err(format!("every point has {name} = {lo}: a profile, not a 2-D topography"));
        }
        let step = (hi - lo) / (n - 1) as f64;
        for (k, &v) in lines.iter().enumerate() {
            if ((v - lo) / step - k as f64).abs() > OFF_NODE {
                return Err(format!(
                    "the {name} coordinates are not equally spaced ({name} = {v} is off the grid of \
                     {n} lines from {lo} to {hi}): not a regular grid"
                ));
            }
        }
        Ok(Axis { origin: lo, step, n })
    }

    /// Index of the grid line `v` lies on (`v` is one of the values the axis was inferred from).
    fn node(&self, v: f64) -> usize {
        (((v - self.origin) / self.step).round() as usize).min(self.n - 1)
    }
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::super::text::testing;
    use super::*;

    #[test]
    fn samples_fill_their_grids() {
        let ch = Xyz.read(&testing::sample("xyz-1.txt")).unwrap();
        assert_eq!(ch[0].data.dim(), (4, 4));
        // x = 1, y = 2 holds 2; x = 2, y = 1 holds 1.
        assert_eq!(ch[0].data[(2, 1)], 2.0);
        assert_eq!(ch[0].data[(1, 2)], 1.0);
        assert_eq!(ch[0].data.sum(), 18.0);
        let ch = Xyz.read(&testing::sample("xyz-2.txt")).unwrap();
        assert!(ch[0].data[(0, 1)].is_nan() && ch[0].data[(1, 2)].is_nan());
        assert_eq!(ch[0].data.iter().filter(|v| v.is_nan()).count(), 2);
    }

    #[test]
    fn shuffled_rounded_points_are_a_grid() {
        let ch = Xyz
            .read(b"0.2 0 3\n0 0 1\n0.1 0 2\n0.30000000000000004 0 4\n0 1e-3 5\n0.1 1e-3 6\n0.2 1e-3 7\n0.3 1e-3 8\n")
            .unwrap();
        assert_eq!(ch[0].data.as_slice().unwrap(), &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0]);
    }

    #[test]
    fn irregular_sets_are_refused() {
        let e = Xyz.read(b"0 0 1\n1 0 1\n3 0 1\n0 1 1\n1 1 1\n3 1 1\n").unwrap_err();
        assert!(e.contains("x coordinates are not equally spaced"), "{e}");
        let e = Xyz.read(b"0 0 1\n1 0 1\n0 1 1\n").unwrap_err();
        assert!(e.contains("3 points do not fill a regular grid: their coordinates span 2 × 2 nodes"), "{e}");
        let e = Xyz.read(b"0 0 1\n1 0 1\n0 1 1\n0 1 2\n").unwrap_err();
        assert!(e.contains("span 2 × 2") || e.contains("two points"), "{e}");
        let e = Xyz.read(b"0 0 1\n1 0 1\n2 0 1\n").unwrap_err();
        assert!(e.contains("a profile"), "{e}");
        // A huge span makes no huge grid: x = 0 and 1 are one grid line of a span of 10^12.
        let e = Xyz.read(b"0 0 1\n1 0 1\n1e12 0 1\n0 1 1\n").unwrap_err();
        assert!(e.contains("two points lie on the grid node x = 1, y = 0"), "{e}");
        assert!(Xyz.read(b"0 0\n1 1\n").unwrap_err().contains("not the 3"));
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(256))]
        #[test]
        fn arbitrary_text_never_panics(bytes in testing::texts()) {
            prop_assert!(testing::one_line(&Xyz.read(&bytes)));
        }

        #[test]
        fn mutated_sample_never_panics(edits in testing::edits()) {
            let bytes = testing::apply(testing::sample("xyz-2.txt"), &edits);
            prop_assert!(testing::one_line(&Xyz.read(&bytes)));
        }
    }
}
