//! Contact patches: 4-connected clusters of contact pixels, wrapping across the edges of a
//! periodic window.
//!
//! Imports nothing inside `contact`; must not import friction, study, report, plot, shs, cli.

/// Label the clusters of `mask` (row-major, ny × nx). Returns one label per pixel (0 outside
/// the mask, 1… inside, numbered in order of first appearance) and the size of each cluster
/// in pixels (index = label − 1).
pub fn label(mask: &[bool], (ny, nx): (usize, usize), periodic: bool) -> (Vec<u32>, Vec<usize>) {
    assert_eq!(mask.len(), ny * nx);
    let mut parent: Vec<usize> = (0..mask.len()).collect();
    let join = |a: usize, b: usize, parent: &mut Vec<usize>| {
        let (ra, rb) = (root(parent, a), root(parent, b));
        if ra != rb {
            // Keep the smaller index as root so labels follow the raster order.
            let (lo, hi) = if ra < rb { (ra, rb) } else { (rb, ra) };
            parent[hi] = lo;
        }
    };
    for y in 0..ny {
        for x in 0..nx {
            let i = y * nx + x;
            if !mask[i] {
                continue;
            }
            if x + 1 < nx {
                if mask[i + 1] {
                    join(i, i + 1, &mut parent);
                }
            } else if periodic && nx > 1 && mask[y * nx] {
                join(i, y * nx, &mut parent);
            }
            if y + 1 < ny {
                if mask[i + nx] {
                    join(i, i + nx, &mut parent);
                }
            } else if periodic && ny > 1 && mask[x] {
                join(i, x, &mut parent);
            }
        }
    }
    let mut labels = vec![0u32; mask.len()];
    let mut id_of_root = vec![0u32; mask.len()];
    let mut sizes = Vec::new();
    for i in 0..mask.len() {
        if mask[i] {
            let r = root(&mut parent, i);
            if id_of_root[r] == 0 {
                sizes.push(0);
                id_of_root[r] = sizes.len() as u32;
            }
            labels[i] = id_of_root[r];
            sizes[id_of_root[r] as usize - 1] += 1;
        }
    }
    (labels, sizes)
}

/// Root of `i` with path halving.
fn root(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mask(rows: &[&str]) -> (Vec<bool>, (usize, usize)) {
        let ny = rows.len();
        let nx = rows[0].len();
        (rows.iter().flat_map(|r| r.bytes().map(|b| b == b'#')).collect(), (ny, nx))
    }

    #[test]
    fn four_connected_not_diagonal() {
        let (m, shape) = mask(&["#..#", ".#..", "....", "##.#"]);
        let (_, sizes) = label(&m, shape, false);
        assert_eq!(sizes, vec![1, 1, 1, 2, 1]);
    }

    #[test]
    fn periodic_wrap_joins_edges() {
        let (m, shape) = mask(&["#..#", "....", "....", "#..."]);
        let (labels, sizes) = label(&m, shape, true);
        assert_eq!(sizes, vec![3]);
        assert!(labels.iter().filter(|&&l| l > 0).all(|&l| l == 1));
        let (_, open) = label(&m, shape, false);
        assert_eq!(open, vec![1, 1, 1]);
    }

    #[test]
    fn u_shape_merges_late() {
        let (m, shape) = mask(&["#.#", "#.#", "###"]);
        let (labels, sizes) = label(&m, shape, false);
        assert_eq!(sizes, vec![7]);
        assert_eq!(labels[2], 1);
    }
}
