//! K, the Cerruti operator on the contact points (through the transforms or as a dense
//! matrix), and its near inverse, the solve's preconditioner.
//!
//! Imports `disk` and `influence` inside `contact`; must not import friction, study, report, plot,
//! shs, cli.

use rayon::prelude::*;

use super::disk::CHUNK;
use crate::contact::influence::{Boundary, Offsets, ShearCompliance, TangentialInfluence};

/// Changes at k points are added pair by pair ([`ShearOperator::add_changes`]) while k times
/// the contact points is at most this many times the transform's grid points. Measured at
/// 1500², 31.6 mN (24 206 points, 2 cores): an application 13.8 ms, 85 changes 5 ms — a pair
/// costs about 0.4 of a grid point of an application.
const PAIRS_PER_POINT: usize = 2;

/// The dense operator's memory limit [bytes]: three coefficients per pair of points, in double
/// precision and their copy in single (36 bytes a pair).
const DENSE_BYTES: usize = 384 << 20;

/// Whether K on `m` points costs less as a dense matrix (m² coefficient triples streamed from
/// memory per application) than through the transforms of a grid of `g` points, within the
/// memory limit. The break-even m² ≈ 0.4 g log₂ g is measured: at 256² periodic the dense
/// matrix is 4.7× faster on 292 points and several times slower on 2 500.
pub(super) fn dense_is_cheaper(m: usize, g: usize) -> bool {
    let g = g as f64;
    36 * m * m <= DENSE_BYTES && (m * m) as f64 <= 0.4 * g * g.log2()
}

/// The most bytes a dense operator takes with a transform grid of at most `g` points
/// ([`dense_is_cheaper`]).
pub(super) fn dense_bytes_at_most(g: usize) -> u64 {
    let pairs = (0.4 * g as f64 * (g.max(2) as f64).log2()).min((DENSE_BYTES / 36) as f64);
    36 * pairs as u64
}

/// K on the contact points.
pub(super) enum ShearOperator {
    /// Through the transforms of the contact set's bounding box: the points' flat indices in
    /// the box, and the box's input and output grids (x, y). The transforms run in single
    /// precision, on the operator's copy made on first use, while `in_single` holds.
    Grid {
        influence: Box<TangentialInfluence>,
        single: Option<Box<TangentialInfluence<f32>>>,
        in_single: bool,
        local: Vec<usize>,
        field_in: [Vec<f64>; 2],
        field_out: [Vec<f64>; 2],
        /// K's coefficients at every offset within the box, for the changes of a few points
        /// ([`ShearOperator::add_changes`]), and each point's (y, x) in the box.
        offsets: Offsets,
        cells: Vec<[i32; 2]>,
    },
    /// As a dense matrix: the (xx, xy, yy) coefficients of every pair, row-major [m/Pa]. An
    /// application streams them from memory: while `in_single` holds it streams their single
    /// precision copy (made on first use), half the bytes, and sums in double. A `local` one
    /// (the few points near changed bounds, made for one solve) stays in double: its copy would
    /// cost as much as its solve (at 1500², 100 mN its onset took 15 % longer).
    Dense { m: usize, coefficients: Vec<[f64; 3]>, single: Option<Vec<[f32; 3]>>, in_single: bool, local: bool },
}

impl ShearOperator {
    /// K on `points` (flat indices y·nx + x of an (ny, nx) window of size `size` [m]) through
    /// the transforms of their bounding box only (exactly: see TangentialInfluence::window);
    /// the points are indexed in the box.
    pub(super) fn grid(
        points: &[usize],
        (ny, nx): (usize, usize),
        size: (f64, f64),
        c: ShearCompliance,
        boundary: Boundary,
    ) -> Self {
        let (y0, y1) = points.iter().fold((ny, 0), |(a, b), &i| (a.min(i / nx), b.max(i / nx)));
        let (x0, x1) = points.iter().fold((nx, 0), |(a, b), &i| (a.min(i % nx), b.max(i % nx)));
        let mut influence = TangentialInfluence::window((ny, nx), size, c, boundary, (y1 - y0 + 1, x1 - x0 + 1));
        let (by, bx) = influence.shape();
        let (y0, x0) = (y0.min(ny - by), x0.min(nx - bx));
        let local: Vec<usize> = points.iter().map(|&i| (i / nx - y0) * bx + (i % nx - x0)).collect();
        let cells = local.iter().map(|&c| [(c / bx) as i32, (c % bx) as i32]).collect();
        ShearOperator::Grid {
            offsets: influence.offsets(),
            cells,
            influence: Box::new(influence),
            single: None,
            in_single: false,
            local,
            field_in: [vec![0.0; by * bx], vec![0.0; by * bx]],
            field_out: [vec![0.0; by * bx], vec![0.0; by * bx]],
        }
    }

    /// Whether `out += K Δ` for changes at `k` of the points costs less through
    /// [`add_changes`](Self::add_changes) than an application ([`PAIRS_PER_POINT`]).
    pub(super) fn changes_are_cheaper(&self, k: usize) -> bool {
        match self {
            ShearOperator::Grid { influence, local, .. } => {
                k * local.len() <= PAIRS_PER_POINT * influence.transform_points()
            }
            ShearOperator::Dense { .. } => true,
        }
    }

    /// K on the points `near` (indices into its points) alone, as a dense matrix.
    pub(super) fn subset(&self, near: &[usize]) -> ShearOperator {
        let n = near.len();
        let mut coefficients = Vec::with_capacity(n * n);
        match self {
            ShearOperator::Grid { offsets, cells, .. } => {
                for &i in near {
                    let [yi, xi] = cells[i];
                    coefficients.extend(near.iter().map(|&j| {
                        let [yj, xj] = cells[j];
                        offsets.at((yi - yj) as i64, (xi - xj) as i64)
                    }));
                }
            }
            ShearOperator::Dense { m, coefficients: all, .. } => {
                for &i in near {
                    coefficients.extend(near.iter().map(|&j| all[i * m + j]));
                }
            }
        }
        ShearOperator::Dense { m: n, coefficients, single: None, in_single: false, local: true }
    }

    /// `out += K Δ` on the contact points, for the changes Δ at a few points (point, Δ):
    /// exact in double precision, one pass over the contact points per change.
    pub(super) fn add_changes(&self, changes: &[(usize, [f64; 2])], out: &mut [[f64; 2]]) {
        if changes.is_empty() {
            return;
        }
        let add = |o: &mut [f64; 2], k: [f64; 3], d: [f64; 2]| {
            o[0] += k[0] * d[0] + k[1] * d[1];
            o[1] += k[1] * d[0] + k[2] * d[1];
        };
        match self {
            ShearOperator::Grid { offsets, cells, .. } => {
                let sources: Vec<([i32; 2], [f64; 2])> = changes.iter().map(|&(j, d)| (cells[j], d)).collect();
                out.par_chunks_mut(CHUNK).zip(cells.par_chunks(CHUNK)).for_each(|(out, cells)| {
                    for &([yj, xj], d) in &sources {
                        for (o, &[y, x]) in out.iter_mut().zip(cells) {
                            add(o, offsets.at((y - yj) as i64, (x - xj) as i64), d);
                        }
                    }
                });
            }
            ShearOperator::Dense { m, coefficients, .. } => {
                let m = *m;
                out.par_iter_mut().enumerate().with_min_len((CHUNK / changes.len()).max(1)).for_each(|(i, o)| {
                    changes.iter().for_each(|&(j, d)| add(o, coefficients[i * m + j], d));
                });
            }
        }
    }

    /// Apply K in single precision from now on (`true`) or in double; whether that changed
    /// anything.
    pub(super) fn set_single(&mut self, on: bool) -> bool {
        match self {
            ShearOperator::Grid { influence, single, in_single, .. } => {
                if on == *in_single {
                    return false;
                }
                if on && single.is_none() {
                    *single = Some(Box::new(influence.single()));
                }
                *in_single = on;
            }
            ShearOperator::Dense { coefficients, single, in_single, local, .. } => {
                if on == *in_single || *local {
                    return false;
                }
                if on && single.is_none() {
                    *single = Some(coefficients.par_iter().map(|k| k.map(|v| v as f32)).collect());
                }
                *in_single = on;
            }
        }
        true
    }

    /// `out = K v` on the contact points.
    pub(super) fn apply(&mut self, v: &[[f64; 2]], out: &mut [[f64; 2]]) {
        match self {
            ShearOperator::Grid { influence, single, in_single, local, field_in, field_out, .. } => {
                // Points off the contact set are never written: the input grids stay zero there.
                for (&i, v) in local.iter().zip(v) {
                    field_in[0][i] = v[0];
                    field_in[1][i] = v[1];
                }
                let [ox, oy] = field_out;
                match single.as_mut().filter(|_| *in_single) {
                    Some(single) => single.apply([&field_in[0], &field_in[1]], [ox, oy]),
                    None => influence.apply([&field_in[0], &field_in[1]], [ox, oy]),
                }
                out.par_iter_mut().zip(local.par_iter()).with_min_len(CHUNK).for_each(|(o, &i)| *o = [ox[i], oy[i]]);
            }
            ShearOperator::Dense { m, coefficients, single, in_single, .. } => {
                let m = *m;
                match single.as_ref().filter(|_| *in_single) {
                    Some(single) => dense_product(m, single, v, out),
                    None => dense_product(m, coefficients, v, out),
                }
            }
        }
    }

    /// The same operator with the row transforms of the box's rows without contact points
    /// skipped: their tractions are zero and their displacements not wanted.
    pub(super) fn only_contact_rows(mut self) -> Self {
        if let ShearOperator::Grid { influence, local, .. } = &mut self {
            let (by, bx) = influence.shape();
            let mut rows = vec![false; by];
            local.iter().for_each(|&i| rows[i / bx] = true);
            influence.only_rows(rows);
        }
        self
    }

    /// The same operator as a dense matrix, from the grid operator's responses to a unit
    /// traction at the box's corner: the kernel is even in each offset (xx, yy) or odd in
    /// each (xy), so these give every pair.
    pub(super) fn dense(self) -> Self {
        let ShearOperator::Grid { influence, local, offsets, .. } = &self else { return self };
        let bx = influence.shape().1;
        let m = local.len();
        let mut coefficients = Vec::with_capacity(m * m);
        for &i in local.iter() {
            let (yi, xi) = ((i / bx) as i64, (i % bx) as i64);
            for &j in local.iter() {
                coefficients.push(offsets.at(yi - (j / bx) as i64, xi - (j % bx) as i64));
            }
        }
        ShearOperator::Dense { m, coefficients, single: None, in_single: false, local: false }
    }
}

/// Independent partial sums per row of the dense product: one running sum waits on its last
/// addition at every pair (the product ran at the adder's latency: 74 % of a 512², 10 mN onset
/// on 984 points was that wait); four keep the multipliers busy.
const LANES: usize = 4;

/// `out = K v` for the dense matrix of `m` points with `coefficients` (f64, or f32 read as
/// f64: the sums stay in double precision, the coefficients round to 6e-8 of themselves, and
/// single precision halves the bytes streamed).
fn dense_product<T: Copy + Into<f64> + Sync>(m: usize, coefficients: &[[T; 3]], v: &[[f64; 2]], out: &mut [[f64; 2]]) {
    let add = |[x, y]: [f64; 2], k: &[T; 3], v: &[f64; 2]| {
        let k = k.map(Into::into);
        [x + k[0] * v[0] + k[1] * v[1], y + k[1] * v[0] + k[2] * v[1]]
    };
    out.par_iter_mut().with_min_len((CHUNK / m).max(1)).enumerate().for_each(|(i, o)| {
        let row = &coefficients[i * m..(i + 1) * m];
        let (rows, vs) = (row.chunks_exact(LANES), v.chunks_exact(LANES));
        let tail = rows.remainder().iter().zip(vs.remainder()).fold([0.0; 2], |s, (k, v)| add(s, k, v));
        let lanes = rows.zip(vs).fold([[0.0; 2]; LANES], |mut s, (k, v)| {
            for l in 0..LANES {
                s[l] = add(s[l], &k[l], &v[l]);
            }
            s
        });
        *o = lanes.iter().fold(tail, |[x, y], s| [x + s[0], y + s[1]]);
    });
}

/// Offsets of K's inverse the preconditioner keeps: |dy|, |dx| ≤ this many pixels. On the
/// stuck problem of the 1500² stand-in ball at 10 mN (a scalar 1/q kernel, 7 952 points) the
/// conjugate gradient takes 36 iterations without, 15 with radius 1, 16 with 2, 14 with 4 and
/// 12 with the whole inverse (an FFT pair more per iteration); at 256², 100 mN the sliding
/// onset takes 2 647, 2 642 and 2 590 applications with radius 1, 2 and 4 (3 681 without);
/// with the stand-in ball and its wafer at 1500² (mu_s 0.6, mu_d 0.4) radius 4 against 2
/// takes 3 483 against 3 922 at 10 mN, 3 884 against 4 491 at 31.6 mN and 6 130 against 7 681
/// at 100 mN (160 against 197 s); radius 6 at 31.6 mN 3 696.
const NEAR: usize = 4;

/// K's inverse near the diagonal on the contact points, scaled to 1 on it (its xx
/// coefficient at zero offset): the inverse is short-ranged (the traction under a unit
/// displacement falls off as 1/r³, where K's displacement under a unit traction falls as
/// 1/r), so its nearest offsets give most of it. Applied to the free gradient, it damps the
/// rough modes K leaves slow, at the cost of a pass over the points' neighbours.
pub(super) struct NearInverse {
    /// The kept offsets' coefficients (xx, xy, yy).
    coefficients: Vec<[f64; 3]>,
    /// Each point's neighbours within the kept offsets, itself among them, as (point, index
    /// into `coefficients`): point i's are `neighbours[first[i]..first[i + 1]]`. Listed once,
    /// so that an application reads only the points that are there instead of looking up every
    /// offset in the box's grid.
    first: Vec<usize>,
    neighbours: Vec<(u32, u32)>,
}

impl NearInverse {
    pub(super) fn of(operator: &ShearOperator) -> Self {
        let ShearOperator::Grid { influence, local, .. } = operator else { unreachable!("made on the grid") };
        Self::with_taps(&Self::taps(influence), local, influence.shape())
    }

    /// K's inverse at offsets up to [`NEAR`] pixels, scaled to 1 on the diagonal; the diagonal
    /// alone should the truncation lose positivity.
    fn taps(influence: &TangentialInfluence) -> Vec<((i64, i64), [f64; 3])> {
        let mut taps = influence.inverse_near(NEAR);
        let centre = taps.iter().find(|(d, _)| *d == (0, 0)).expect("the zero offset").1[0];
        taps.iter_mut().for_each(|(_, g)| *g = g.map(|v| v / centre));
        if centre > 0.0 && positive(&taps) {
            taps
        } else {
            vec![((0, 0), [1.0, 0.0, 1.0])]
        }
    }

    /// The operator with coefficients `taps` on the points at cells `cells` (y · bx + x) of a
    /// box of shape (by, bx).
    pub(super) fn with_taps(taps: &[((i64, i64), [f64; 3])], cells: &[usize], (by, bx): (usize, usize)) -> Self {
        let mut point_at = vec![u32::MAX; by * bx];
        cells.iter().enumerate().for_each(|(j, &c)| point_at[c] = j as u32);
        let (by, bx) = (by as i64, bx as i64);
        let mut first = Vec::with_capacity(cells.len() + 1);
        let mut neighbours = Vec::new();
        for &c in cells {
            first.push(neighbours.len());
            let (y, x) = (c as i64 / bx, c as i64 % bx);
            for (t, ((dy, dx), _)) in taps.iter().enumerate() {
                let (yy, xx) = (y + dy, x + dx);
                if (0..by).contains(&yy) && (0..bx).contains(&xx) {
                    let j = point_at[(yy * bx + xx) as usize];
                    if j != u32::MAX {
                        neighbours.push((j, t as u32));
                    }
                }
            }
        }
        first.push(neighbours.len());
        NearInverse { coefficients: taps.iter().map(|t| t.1).collect(), first, neighbours }
    }

    /// The same operator on the points `near` (indices into the `m` points) alone.
    pub(super) fn subset(&self, near: &[usize], m: usize) -> Self {
        let mut index = vec![u32::MAX; m];
        near.iter().enumerate().for_each(|(k, &i)| index[i] = k as u32);
        let mut first = Vec::with_capacity(near.len() + 1);
        let mut neighbours = Vec::new();
        for &i in near {
            first.push(neighbours.len());
            for &(j, t) in &self.neighbours[self.first[i]..self.first[i + 1]] {
                if index[j as usize] != u32::MAX {
                    neighbours.push((index[j as usize], t));
                }
            }
        }
        first.push(neighbours.len());
        NearInverse { coefficients: self.coefficients.clone(), first, neighbours }
    }

    /// `out = N v` on the contact points.
    pub(super) fn apply(&self, v: &[[f64; 2]], out: &mut [[f64; 2]]) {
        out.par_iter_mut().enumerate().with_min_len(CHUNK).for_each(|(i, o)| {
            *o = self.neighbours[self.first[i]..self.first[i + 1]].iter().fold([0.0; 2], |[ax, ay], &(j, t)| {
                let (w, g) = (v[j as usize], self.coefficients[t as usize]);
                [ax + g[0] * w[0] + g[1] * w[1], ay + g[1] * w[0] + g[2] * w[1]]
            });
        });
    }
}

/// Whether the 2×2 symbol of `taps` (a kernel even in each offset along the diagonal, odd in
/// each across it) is positive definite at every wavevector of a 33 × 33 sampling of
/// [0, π]² (the symbol is even in each component): then so is N on any set of points.
fn positive(taps: &[((i64, i64), [f64; 3])]) -> bool {
    const SAMPLES: usize = 32;
    let angle = |i: usize| std::f64::consts::PI * i as f64 / SAMPLES as f64;
    (0..=SAMPLES).all(|a| {
        (0..=SAMPLES).all(|b| {
            let (ky, kx) = (angle(a), angle(b));
            let s = taps.iter().fold([0.0; 3], |s, ((dy, dx), g)| {
                let c = (ky * *dy as f64 + kx * *dx as f64).cos();
                [s[0] + g[0] * c, s[1] + g[1] * c, s[2] + g[2] * c]
            });
            s[0] > 0.0 && s[0] * s[2] - s[1] * s[1] > 0.0
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Skipping the rows without contact points changes no bit of K v on the points, in
    /// single and double precision, on both boundaries.
    #[test]
    fn skipping_rows_without_points_changes_nothing() {
        let c = ShearCompliance { a: 1.0 / 50e9, b: 0.26 / 50e9 };
        let n = 96;
        // Two patches in rows 10–14 and 60–61 of a box from row 10 to 61, columns 5 to 80.
        let points: Vec<usize> =
            (10..15).chain(60..62).flat_map(|y| (5..81).step_by(3).map(move |x| y * n + x)).collect();
        let m = points.len();
        let v: Vec<[f64; 2]> = (0..m).map(|i| [((i * 37) % 11) as f64 - 5.0, ((i * 17) % 7) as f64 - 3.0]).collect();
        for boundary in [Boundary::Periodic, Boundary::Free] {
            for single in [false, true] {
                let mut results = Vec::new();
                for skip in [false, true] {
                    let mut op = ShearOperator::grid(&points, (n, n), (9.6e-6, 9.6e-6), c, boundary);
                    if skip {
                        op = op.only_contact_rows();
                    }
                    op.set_single(single);
                    let mut out = vec![[0.0; 2]; m];
                    op.apply(&v, &mut out);
                    results.push(out);
                }
                assert!(results[0].iter().any(|u| u[0] != 0.0));
                assert_eq!(results[0], results[1], "{boundary:?}, single {single}");
            }
        }
    }

    /// With every offset of a periodic window (odd sides, so that each periodic offset is one
    /// tap; rectangular pixels), the near inverse is K's inverse: it takes the displacement
    /// K q back to q, less q's mean (the mode the periodic kernel leaves out).
    #[test]
    fn near_inverse_with_every_offset_is_ks_inverse() {
        let c = ShearCompliance { a: 1.0 / 50e9, b: 0.26 / 50e9 };
        let n = 15;
        let mut influence = TangentialInfluence::periodic(n, n, (3.0e-6, 2.2e-6), c);
        let q: [Vec<f64>; 2] = std::array::from_fn(|k| {
            (0..n * n).map(|i| 1e6 * (((i * (37 + 6 * k)) % 11) as f64 - 5.0 + 0.3 * k as f64)).collect()
        });
        let mut u = [vec![0.0; n * n], vec![0.0; n * n]];
        let [ux, uy] = &mut u;
        influence.apply([&q[0], &q[1]], [ux, uy]);
        let taps = influence.inverse_near(n / 2);
        assert_eq!(taps.len(), n * n);
        let mean = q.each_ref().map(|q| q.iter().sum::<f64>() / (n * n) as f64);
        let wrap = |i: usize, d: i64| (i as i64 + d).rem_euclid(n as i64) as usize;
        for y in 0..n {
            for x in 0..n {
                let back = taps.iter().fold([0.0; 2], |[a, b], ((dy, dx), g)| {
                    let j = wrap(y, *dy) * n + wrap(x, *dx);
                    [a + g[0] * u[0][j] + g[1] * u[1][j], b + g[1] * u[0][j] + g[2] * u[1][j]]
                });
                for k in 0..2 {
                    let want = q[k][y * n + x] - mean[k];
                    assert!((back[k] - want).abs() <= 1e-9 * 5e6, "({y}, {x}) component {k}: {} vs {want}", back[k]);
                }
            }
        }
    }

    /// The sampled symbol accepts the inverse's nearest offsets and refuses a stencil whose
    /// neighbours outweigh its centre.
    #[test]
    fn near_inverse_is_positive_and_a_heavy_stencil_is_not() {
        let c = ShearCompliance { a: 1.0 / 50e9, b: 0.26 / 50e9 };
        let points: Vec<usize> = (0..64 * 64).collect();
        let operator = ShearOperator::grid(&points, (64, 64), (1.3e-6, 1.3e-6), c, Boundary::Periodic);
        let ShearOperator::Grid { influence, .. } = &operator else { unreachable!("made on the grid") };
        let taps = NearInverse::taps(influence);
        assert_eq!(taps.len(), (2 * NEAR + 1).pow(2), "the truncated inverse, not the diagonal alone");
        assert!(taps.iter().any(|(d, g)| *d == (0, 0) && g[0] == 1.0));
        let heavy: Vec<_> = [(0, 0), (0, 1), (0, -1), (1, 0), (-1, 0)]
            .into_iter()
            .map(|d| (d, if d == (0, 0) { [1.0, 0.0, 1.0] } else { [-0.3, 0.0, -0.3] }))
            .collect();
        assert!(!positive(&heavy));
        assert!(positive(&heavy[..1]));
    }

    /// The dense product in partial sums is the row-by-row sum, with a row length that leaves
    /// a tail (7 = 4 + 3); its single precision copy is within the coefficients' rounding; a
    /// local subset stays in double.
    #[test]
    fn dense_product_sums_every_pair_once() {
        let m = 7;
        let coefficients: Vec<[f64; 3]> = (0..m * m)
            .map(|k| [1.0 + (k % 5) as f64 / 3.0, ((k * 7) % 11) as f64 / 7.0 - 0.6, 2.0 + (k % 3) as f64 / 9.0])
            .collect();
        let v: Vec<[f64; 2]> = (0..m).map(|i| [i as f64 - 2.5, 1.0 / (1.0 + i as f64)]).collect();
        let want: Vec<[f64; 2]> = (0..m)
            .map(|i| {
                (0..m).fold([0.0; 2], |[x, y], j| {
                    let k = coefficients[i * m + j];
                    [x + k[0] * v[j][0] + k[1] * v[j][1], y + k[1] * v[j][0] + k[2] * v[j][1]]
                })
            })
            .collect();
        let mut operator = ShearOperator::Dense { m, coefficients, single: None, in_single: false, local: false };
        let close = |got: &[[f64; 2]], within: f64| {
            got.iter().zip(&want).all(|(g, w)| (g[0] - w[0]).abs() <= within && (g[1] - w[1]).abs() <= within)
        };
        let mut got = vec![[0.0; 2]; m];
        operator.apply(&v, &mut got);
        assert!(close(&got, 1e-12), "{got:?} vs {want:?}");
        assert!(operator.set_single(true));
        operator.apply(&v, &mut got);
        assert!(close(&got, 1e-5) && !close(&got, 1e-12), "single: {got:?} vs {want:?}");
        let mut local = operator.subset(&[0, 2, 3]);
        assert!(!local.set_single(true), "a local subset stays in double");
    }

    /// Changes at a few points added pair by pair give what an application of K to them gives,
    /// on the grid operator of both boundaries and on the dense operator.
    #[test]
    fn changes_added_pair_by_pair_are_k_applied() {
        let c = ShearCompliance { a: 1.0 / 50e9, b: 0.26 / 50e9 };
        let n = 64;
        let points: Vec<usize> = (0..n * n).filter(|i| (i * 7919) % 5 < 2 && i % n > 3).collect();
        for boundary in [Boundary::Periodic, Boundary::Free] {
            for (m, dense) in [(points.len(), false), (60, true)] {
                let mut op = ShearOperator::grid(&points[..m], (n, n), (6.4e-6, 6.4e-6), c, boundary);
                if dense {
                    op = op.dense();
                }
                let changes: Vec<(usize, [f64; 2])> = [3, m / 3, m / 2 + 1, m - 1]
                    .iter()
                    .map(|&j| (j, [1e8 * (1.0 + j as f64 / m as f64), -3e7]))
                    .collect();
                let mut v = vec![[0.0; 2]; m];
                changes.iter().for_each(|&(j, d)| v[j] = d);
                let mut want = vec![[0.0; 2]; m];
                op.apply(&v, &mut want);
                let scale = want.iter().map(|w| w[0].abs().max(w[1].abs())).fold(0.0, f64::max);
                assert!(scale > 0.0);
                // Added to what is there: twice K v.
                let mut got = want.clone();
                op.add_changes(&changes, &mut got);
                for (g, w) in got.iter().zip(&want) {
                    assert!(
                        (g[0] - 2.0 * w[0]).abs() <= 1e-12 * scale && (g[1] - 2.0 * w[1]).abs() <= 1e-12 * scale,
                        "{boundary:?}, dense {dense}: {g:?} vs twice {w:?}"
                    );
                }
            }
        }
    }
}
