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
}
