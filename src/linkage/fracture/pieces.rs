//! Pieces of a body that no support holds: connected components of its intact members.

/// The connected components (over the members with `intact[m]`) of the nodes not in
/// `removed` that hold no supported node (`supported[node]`): each a list of nodes, ascending,
/// the lists ordered by their first node. A node without intact members is a piece of its own.
pub fn unsupported_pieces(
    node_count: usize,
    members: &[[usize; 2]],
    intact: &[bool],
    supported: &[bool],
    removed: &[bool],
) -> Vec<Vec<usize>> {
    let mut parent: Vec<usize> = (0..node_count).collect();
    fn root(parent: &mut [usize], mut x: usize) -> usize {
        while parent[x] != x {
            parent[x] = parent[parent[x]];
            x = parent[x];
        }
        x
    }
    for (m, &[a, b]) in members.iter().enumerate() {
        if intact[m] {
            let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
            if ra != rb {
                parent[ra.max(rb)] = ra.min(rb);
            }
        }
    }
    let mut held = vec![false; node_count];
    for (n, _) in supported.iter().enumerate().filter(|(_, s)| **s) {
        let r = root(&mut parent, n);
        held[r] = true;
    }
    // Roots are the smallest node of their component (unions keep the smaller root), so
    // pieces come out ordered by their first node.
    let mut index = vec![usize::MAX; node_count];
    let mut pieces: Vec<Vec<usize>> = Vec::new();
    for (n, _) in removed.iter().enumerate().filter(|(_, r)| !**r) {
        let r = root(&mut parent, n);
        if held[r] {
            continue;
        }
        if index[r] == usize::MAX {
            index[r] = pieces.len();
            pieces.push(Vec::new());
        }
        pieces[index[r]].push(n);
    }
    pieces
}

/// What no longer holds on after a break that left the stiffness singular: a piece is a
/// connected part without supports; a node without supports on fewer intact members than `d`
/// (the DOFs per node: a 2D node hanging on one member, a 3D node on two) turns freely about
/// them and goes with its members. Repeated until nothing more comes loose. Nodes already in
/// `removed` are not found again. Returns the released nodes grouped by the members they had
/// before the break (intact or not), nodes ascending, pieces by first node; empty when the
/// singular mode is elsewhere.
pub fn released_pieces(
    members: &[[usize; 2]],
    intact: &[bool],
    supported: &[bool],
    removed: &[bool],
    d: usize,
) -> Vec<Vec<usize>> {
    let node_count = supported.len();
    let mut intact = intact.to_vec();
    let mut gone = removed.to_vec();
    let mut released = vec![false; node_count];
    loop {
        let mut count = vec![0usize; node_count];
        for (m, &[a, b]) in members.iter().enumerate() {
            if intact[m] {
                count[a] += 1;
                count[b] += 1;
            }
        }
        let mut loose: Vec<usize> = (0..node_count)
            .filter(|&n| !gone[n] && !supported[n] && count[n] > 0 && count[n] < d)
            .collect();
        let pieces = unsupported_pieces(node_count, members, &intact, supported, &gone);
        loose.extend(pieces.iter().flatten());
        if loose.is_empty() {
            break;
        }
        for &n in &loose {
            gone[n] = true;
            released[n] = true;
        }
        for (j, &[a, b]) in members.iter().enumerate() {
            if gone[a] || gone[b] {
                intact[j] = false;
            }
        }
    }
    let together: Vec<bool> = members
        .iter()
        .map(|&[a, b]| released[a] && released[b])
        .collect();
    let not_released: Vec<bool> = released.iter().map(|r| !r).collect();
    unsupported_pieces(
        node_count,
        members,
        &together,
        &vec![false; node_count],
        &not_released,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_chain_cut_in_the_middle_loses_its_far_end() {
        // 0 - 1 - 2 - 3 - 4, node 0 supported, member 1-2 broken.
        let members = [[0, 1], [1, 2], [2, 3], [3, 4]];
        let intact = [true, false, true, true];
        let supported = [true, false, false, false, false];
        let removed = [false; 5];
        assert_eq!(
            unsupported_pieces(5, &members, &intact, &supported, &removed),
            vec![vec![2, 3, 4]]
        );
        let all = [true; 4];
        assert!(unsupported_pieces(5, &members, &all, &supported, &removed).is_empty());
        // Nodes already removed are not found again.
        let removed = [false, false, true, true, true];
        assert!(unsupported_pieces(5, &members, &intact, &supported, &removed).is_empty());
    }

    #[test]
    fn a_node_left_on_one_member_in_2d_goes_with_its_piece() {
        // Triangle 0-1-2 (0, 1 supported) with node 3 hung from 2 by member 2-3 and from 1 by
        // 1-3; 1-3 broken: node 3 hangs on one member and turns about it.
        let members = [[0, 1], [1, 2], [0, 2], [2, 3], [1, 3]];
        let intact = [true, true, true, true, false];
        let supported = [true, true, false, false];
        let removed = [false; 4];
        assert_eq!(
            released_pieces(&members, &intact, &supported, &removed, 2),
            vec![vec![3]]
        );
        // In 3D node 3 goes first; then node 2 is left on two members and turns too: one
        // piece of both.
        assert_eq!(
            released_pieces(&members, &intact, &supported, &removed, 3),
            vec![vec![2, 3]]
        );
        assert!(released_pieces(&members, &[true; 5], &supported, &removed, 2).is_empty());
    }
}
