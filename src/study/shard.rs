//! Shards: a study's work split between processes (`asperity run --shard I/N`), for a cluster.
//!
//! The work is the study's sweeps (a topography or a coarser copy of it, elastic or plastic,
//! each over the chain of loads). Laid end to end in the study's order, every load of a sweep
//! costs the sweep's grid points; shard I of N takes the stretch of that line from cost
//! (I − 1)·T/N to I·T/N (T the total), each end moved to the nearest load. So every load is
//! solved by exactly one shard, a shard's cost is within one load of the largest grid of T/N,
//! and the assignment depends on nothing but the study and N. A shard's stretch is one or more
//! [`Piece`]s: contiguous parts of load chains, each started cold (no warm start from a load
//! another shard solves).
//!
//! It depends on nothing of the study but grid sizes and load counts: it must not import the
//! study file, the runner's rooms, `plot`, `report`, `cli` or `python`.

use std::fmt;
use std::ops::Range;
use std::str::FromStr;

/// The I-th of N shards (1 ≤ I ≤ N).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// From 1 to `count`.
    pub index: usize,
    /// The number of shards N the study is split into.
    pub count: usize,
}

impl FromStr for Shard {
    type Err = String;

    /// `I/N`, as `--shard` takes it.
    fn from_str(s: &str) -> Result<Shard, String> {
        let quoted = crate::quantity::quoted(s);
        let (i, n) = s.trim().split_once('/').ok_or_else(|| format!("{quoted} is not I/N (e.g. 2/8)"))?;
        let whole = |t: &str| t.trim().parse::<usize>().map_err(|_| format!("{quoted} is not I/N with whole numbers"));
        let (index, count) = (whole(i)?, whole(n)?);
        if count == 0 {
            return Err(format!("{quoted}: the number of shards N must be at least 1"));
        }
        if index == 0 || index > count {
            return Err(format!("{quoted}: the shard I must be from 1 to N = {count}"));
        }
        Ok(Shard { index, count })
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// A contiguous part of one sweep's chain of loads: the loads (indices, ascending) of sweep
/// `sweep`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Piece {
    /// Index of the sweep (a topography or a coarser copy of it, elastic or plastic) in the
    /// study's order.
    pub sweep: usize,
    /// Indices of the loads of this piece, ascending, within the sweep's load list.
    pub loads: Range<usize>,
}

/// The pieces of every shard, in shard order, for sweeps of `points[s]` grid points each over
/// `loads` loads, split into `count` shards. A shard may have none (more shards than loads).
pub fn assign(points: &[usize], loads: usize, count: usize) -> Vec<Vec<Piece>> {
    assert!(count > 0, "at least one shard");
    // Loads in line: item j is load j % loads of sweep j / loads; `before[j]` its cost before it.
    let items = points.len() * loads;
    let mut before = Vec::with_capacity(items + 1);
    before.push(0u128);
    for &p in points {
        for _ in 0..loads {
            before.push(before.last().expect("not empty") + p as u128);
        }
    }
    let total = before[items];
    // Cut i at the load boundary nearest to i·T/N (the earlier of two as near), in whole
    // numbers so that the assignment is the same on every machine.
    let cut = |i: usize| -> usize {
        let target = total * i as u128;
        let n = count as u128;
        let after = before.partition_point(|&c| c * n < target);
        if after > 0 && target - before[after - 1] * n <= before.get(after).map_or(u128::MAX, |&c| c * n - target) {
            after - 1
        } else {
            after.min(items)
        }
    };
    let cuts: Vec<usize> = (0..=count).map(|i| if i == count { items } else { cut(i) }).collect();
    (0..count)
        .map(|i| {
            let (mut j, end) = (cuts[i], cuts[i + 1]);
            let mut pieces = Vec::new();
            while j < end {
                let (sweep, first) = (j / loads, j % loads);
                let last = end.min((sweep + 1) * loads);
                pieces.push(Piece { sweep, loads: first..last - sweep * loads });
                j = last;
            }
            pieces
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cost(points: &[usize], pieces: &[Piece]) -> usize {
        pieces.iter().map(|p| points[p.sweep] * p.loads.len()).sum()
    }

    #[test]
    fn every_load_once_balanced_and_deterministic() {
        // The default study's sweeps: three 1500² balls, their copies 2× and 4× coarser.
        let default = [1500 * 1500; 3].into_iter().chain([750 * 750, 375 * 375].repeat(3)).collect::<Vec<_>>();
        let cases: Vec<(Vec<usize>, usize)> =
            vec![(default, 25), (vec![64 * 64, 32 * 32], 7), (vec![100], 1), (vec![256 * 256; 2], 13)];
        for (points, loads) in &cases {
            let total: usize = points.iter().sum::<usize>() * loads;
            let largest = *points.iter().max().unwrap();
            for count in 1..=40 {
                let shards = assign(points, *loads, count);
                assert_eq!(shards, assign(points, *loads, count));
                assert_eq!(shards.len(), count);
                let mut seen = vec![vec![0; *loads]; points.len()];
                for pieces in &shards {
                    for p in pieces {
                        assert!(!p.loads.is_empty() && p.loads.end <= *loads, "{p:?}");
                        p.loads.clone().for_each(|k| seen[p.sweep][k] += 1);
                    }
                    // Within one load of the largest grid of the even share.
                    let share = total as f64 / count as f64;
                    let c = cost(points, pieces) as f64;
                    assert!((c - share).abs() <= largest as f64, "{count} shards: {c} against {share}");
                }
                assert!(seen.iter().flatten().all(|&n| n == 1), "{count} shards: {seen:?}");
            }
            // One shard: every chain whole.
            let whole: Vec<Piece> = (0..points.len()).map(|sweep| Piece { sweep, loads: 0..*loads }).collect();
            assert_eq!(assign(points, *loads, 1), [whole]);
        }
    }

    #[test]
    fn pieces_as_expected() {
        // Two equal sweeps of 6 loads in 3 shards: 4 loads each, the middle one cut.
        let shards = assign(&[10, 10], 6, 3);
        assert_eq!(
            shards,
            [
                vec![Piece { sweep: 0, loads: 0..4 }],
                vec![Piece { sweep: 0, loads: 4..6 }, Piece { sweep: 1, loads: 0..2 }],
                vec![Piece { sweep: 1, loads: 2..6 }],
            ]
        );
        // A sweep 4× cheaper fills in: 24 + 6 = 30, 10 per shard.
        let shards = assign(&[4, 1], 6, 3);
        assert_eq!(cost(&[4, 1], &shards[0]), 8);
        assert_eq!(shards[2], [Piece { sweep: 0, loads: 5..6 }, Piece { sweep: 1, loads: 0..6 }]);
        // More shards than loads: some have none.
        assert_eq!(assign(&[1], 2, 4).iter().filter(|s| s.is_empty()).count(), 2);
    }

    #[test]
    fn shards_parse() {
        assert_eq!("2/8".parse::<Shard>(), Ok(Shard { index: 2, count: 8 }));
        assert_eq!(" 3 / 3 ".parse::<Shard>().unwrap().to_string(), "3/3");
        for (bad, says) in [("0/3", "from 1 to N"), ("4/3", "from 1 to N"), ("1/0", "at least 1"), ("x", "not I/N")] {
            let e = bad.parse::<Shard>().unwrap_err();
            assert!(e.contains(says) && e.contains(bad), "{bad}: {e}");
        }
        assert!("-1/3".parse::<Shard>().is_err() && "1.5/3".parse::<Shard>().is_err());
    }
}
