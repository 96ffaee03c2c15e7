//! The check of a member list against its nodes (indices, distinct ends, length, repeats), in
//! time linear in the members: a links file of millions of lines is checked on every read.

use crate::linkage::{bounding_diagonal, MemberProblem};
use crate::Real;
use nalgebra::Vector3;

/// Buckets longer than this are sorted to find repeats; shorter ones are scanned pairwise
/// (a lattice node has at most 26 neighbours).
const SCAN_LIMIT: usize = 32;

/// Check members against the nodes: indices in range, two distinct nodes, non-zero
/// length (below 1e-12 of the model size counts as zero), no pair repeated. The problem of
/// the first member (in order) that has one is returned; a repeat names the first member
/// joining the same pair.
pub fn check_members(
    nodes: &[Vector3<Real>],
    members: impl Iterator<Item = [usize; 2]>,
) -> Result<(), MemberProblem> {
    let scale = bounding_diagonal(nodes);
    let mut pairs = Vec::with_capacity(members.size_hint().0);
    let mut problem = None;
    for (i, [a, b]) in members.enumerate() {
        if let Some(p) = single_member_problem(nodes, scale, i, a, b) {
            problem = Some(p);
            break;
        }
        pairs.push([a.min(b), a.max(b)]);
    }
    // Only members before the first single-member problem can be reported as repeats.
    match (first_repeat(nodes.len(), &pairs), problem) {
        (Some(repeat), _) => Err(repeat),
        (None, Some(p)) => Err(p),
        (None, None) => Ok(()),
    }
}

/// What is wrong with member `i` from node `a` to `b` on its own (`scale`: the model's size).
fn single_member_problem(
    nodes: &[Vector3<Real>],
    scale: Real,
    i: usize,
    a: usize,
    b: usize,
) -> Option<MemberProblem> {
    if let Some(&n) = [a, b].iter().find(|&&n| n >= nodes.len()) {
        return Some(MemberProblem::NodeOutOfRange { member: i, node: n });
    }
    if a == b {
        return Some(MemberProblem::SelfMember { member: i, node: a });
    }
    let length = (nodes[b] - nodes[a]).norm();
    if !(length.is_finite() && scale.is_finite()) {
        return Some(MemberProblem::TooLarge { member: i });
    }
    if length <= 1e-12 * scale || length == 0.0 {
        return Some(MemberProblem::ZeroLength { member: i, length });
    }
    None
}

/// The earliest member (by index) whose pair (`[low, high]` node, both below `node_count`)
/// an earlier member already joins, with that first member: members bucketed by their lower
/// node (a counting sort, in member order), each bucket searched for equal upper nodes.
fn first_repeat(node_count: usize, pairs: &[[usize; 2]]) -> Option<MemberProblem> {
    let mut start = vec![0usize; node_count + 1];
    for &[low, _] in pairs {
        start[low + 1] += 1;
    }
    for n in 0..node_count {
        start[n + 1] += start[n];
    }
    let mut fill = start.clone();
    // (upper node, member) per bucket, members ascending within a bucket.
    let mut entries = vec![(0usize, 0usize); pairs.len()];
    for (i, &[low, high]) in pairs.iter().enumerate() {
        entries[fill[low]] = (high, i);
        fill[low] += 1;
    }
    let mut best: Option<(usize, usize)> = None;
    let mut consider = |member: usize, first: usize| {
        if best.is_none_or(|(m, _)| member < m) {
            best = Some((member, first));
        }
    };
    for n in 0..node_count {
        let bucket = &mut entries[start[n]..start[n + 1]];
        if bucket.len() <= SCAN_LIMIT {
            // The first repeat in this bucket: the smallest later member whose upper node an
            // earlier one shares.
            'later: for (k, &(high, member)) in bucket.iter().enumerate() {
                for &(h, first) in &bucket[..k] {
                    if h == high {
                        consider(member, first);
                        break 'later;
                    }
                }
            }
        } else {
            bucket.sort_unstable();
            for w in bucket.windows(2) {
                // Sorted by (upper node, member): the first two of a run are the pair to report.
                if w[0].0 == w[1].0 {
                    consider(w[1].1, w[0].1);
                }
            }
        }
    }
    best.map(|(member, first)| MemberProblem::Duplicate { member, first })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line(n: usize) -> Vec<Vector3<Real>> {
        (0..n).map(|i| Vector3::new(i as Real, 0.0, 0.0)).collect()
    }

    #[test]
    fn a_repeat_names_the_earliest_repeating_member_and_its_first() {
        let nodes = line(5);
        let members = [[0, 1], [1, 2], [2, 3], [3, 2], [1, 0], [0, 1]];
        assert_eq!(
            check_members(&nodes, members.into_iter()),
            Err(MemberProblem::Duplicate {
                member: 3,
                first: 2
            })
        );
    }

    #[test]
    fn the_earlier_of_a_repeat_and_a_single_member_problem_is_reported() {
        let nodes = line(5);
        let repeat_first = [[0, 1], [1, 0], [2, 2]];
        assert_eq!(
            check_members(&nodes, repeat_first.into_iter()),
            Err(MemberProblem::Duplicate {
                member: 1,
                first: 0
            })
        );
        let problem_first = [[0, 1], [2, 2], [1, 0]];
        assert_eq!(
            check_members(&nodes, problem_first.into_iter()),
            Err(MemberProblem::SelfMember { member: 1, node: 2 })
        );
        let out_of_range = [[0, 1], [1, 9], [1, 0]];
        assert_eq!(
            check_members(&nodes, out_of_range.into_iter()),
            Err(MemberProblem::NodeOutOfRange { member: 1, node: 9 })
        );
    }

    #[test]
    fn a_star_of_many_members_is_searched_by_sorting() {
        // Node 0 joined to every other node: one bucket far longer than the scan limit.
        let nodes = line(200);
        let mut members: Vec<[usize; 2]> = (1..200).map(|j| [0, j]).collect();
        assert_eq!(check_members(&nodes, members.iter().copied()), Ok(()));
        members.push([150, 0]);
        members.push([40, 0]);
        assert_eq!(
            check_members(&nodes, members.iter().copied()),
            Err(MemberProblem::Duplicate {
                member: 199,
                first: 149
            })
        );
    }

    #[test]
    fn the_same_answers_as_a_hash_map_on_random_lists() {
        // A simple generator (no dependency): repeats are common among 30 nodes.
        let nodes = line(30);
        let mut state: u64 = 12345;
        let mut next = |m: usize| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 33) as usize) % m
        };
        for _ in 0..300 {
            let count = 1 + next(60);
            let members: Vec<[usize; 2]> = (0..count)
                .map(|_| {
                    let a = next(30);
                    [a, (a + 1 + next(29)) % 30]
                })
                .collect();
            let mut seen = std::collections::HashMap::new();
            let mut expected = Ok(());
            for (i, &[a, b]) in members.iter().enumerate() {
                if let Some(&first) = seen.get(&(a.min(b), a.max(b))) {
                    expected = Err(MemberProblem::Duplicate { member: i, first });
                    break;
                }
                seen.insert((a.min(b), a.max(b)), i);
            }
            assert_eq!(check_members(&nodes, members.iter().copied()), expected);
        }
    }
}
