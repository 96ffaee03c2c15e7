//! Fill-reducing orderings: METIS nested dissection of a graph, and its expansion from nodes to DOFs.
//!
//! Permutations follow faer's convention: `perm[new] = old` and `inv[old] = new`.

use metis_sys::idx_t;

/// Why an ordering could not be computed.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum OrderingError {
    /// The graph arrays are malformed (lengths, offsets or vertex indices out of range).
    #[error("invalid graph: {0}")]
    InvalidGraph(String),
    /// The graph does not fit METIS's index type (`idx_t`, 32 bits in the vendored build).
    #[error("graph too large for METIS: {what} = {value} exceeds the {bits}-bit index limit")]
    TooLarge {
        /// Which quantity overflowed ("vertices" or "adjacency entries").
        what: &'static str,
        /// Its value.
        value: usize,
        /// Width of METIS's `idx_t`.
        bits: u32,
    },
    /// METIS returned an error status.
    #[error("METIS_NodeND failed with status {status} ({meaning})")]
    Metis {
        /// The raw status code (`METIS_ERROR_INPUT` = −2, `METIS_ERROR_MEMORY` = −3, `METIS_ERROR` = −4).
        status: i32,
        /// A short reading of the status.
        meaning: &'static str,
    },
    /// The DOF → node map does not fit the node ordering.
    #[error("invalid DOF groups: {0}")]
    InvalidGroups(String),
}

/// METIS options for one nested dissection; `None` keeps METIS's default.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct MetisOptions {
    /// Seed of METIS's random generator (METIS's default −1 means 4321).
    pub seed: Option<i32>,
    /// Allowed imbalance of a separator's two sides, in thousandths above 1 (METIS's
    /// default for nested dissection: 200, i.e. 1.2).
    pub ufactor: Option<i32>,
}

impl std::fmt::Display for MetisOptions {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match (self.seed, self.ufactor) {
            (None, None) => write!(f, "METIS defaults"),
            (Some(s), None) => write!(f, "METIS seed {s}"),
            (None, Some(u)) => write!(f, "METIS ufactor {u}"),
            (Some(s), Some(u)) => write!(f, "METIS seed {s}, ufactor {u}"),
        }
    }
}

/// The second nested dissection tried on the tree path, side by side with METIS's defaults
/// (see [`best_of_two_orderings`]): another seed, i.e. another draw of the same method. Of
/// the settings direct3 and direct4 measured, only another seed gains on some lattices
/// without being a systematic change; taking the cheaper of the two never loses.
pub const SECOND_ORDERING: MetisOptions = MetisOptions {
    seed: Some(1),
    ufactor: None,
};

/// Nested-dissection ordering of a graph given as CSR adjacency (`xadj` of length
/// `n + 1`, neighbours of vertex `v` in `adjncy[xadj[v]..xadj[v + 1]]`).
///
/// The graph should be symmetric without self loops; it is symmetrized and cleaned
/// (self loops and duplicate edges dropped) before it reaches METIS anyway, because
/// METIS does not check its input and could read out of bounds on an asymmetric graph.
/// Returns `(perm, inv)` with `perm[new] = old` and `inv[old] = new`.
pub fn nested_dissection(
    xadj: &[usize],
    adjncy: &[usize],
) -> Result<(Vec<usize>, Vec<usize>), OrderingError> {
    nested_dissection_with(xadj, adjncy, MetisOptions::default())
}

/// [`nested_dissection`] with METIS options other than its defaults.
pub fn nested_dissection_with(
    xadj: &[usize],
    adjncy: &[usize],
    options: MetisOptions,
) -> Result<(Vec<usize>, Vec<usize>), OrderingError> {
    let n = check_csr(xadj, adjncy)?;
    let mut graph = MetisGraph::new(n, xadj, adjncy)?;
    // No edges: every order is fill-free, and METIS gains nothing.
    if n <= 1 || graph.adjncy.is_empty() {
        let identity: Vec<usize> = (0..n).collect();
        return Ok((identity.clone(), identity));
    }
    let (perm, inv) = metis_node_nd(&mut graph, options)?;
    let perm: Vec<usize> = perm.iter().map(|&p| p as usize).collect();
    let inv: Vec<usize> = inv.iter().map(|&p| p as usize).collect();
    // A wrong permutation from C would corrupt the factorization silently: check it once.
    if !is_inverse_pair(&perm, &inv) {
        return Err(OrderingError::Metis {
            status: 1,
            meaning: "returned an invalid permutation",
        });
    }
    Ok((perm, inv))
}

/// [`nested_dissection`] of the vertices not marked `trailing`, followed by the trailing ones
/// in ascending order: eliminating the others first leaves, in the last block of the
/// Cholesky factor, the factor of the Schur complement on the trailing vertices (used to
/// condense a body on its contact candidates). Returns `(perm, inv)` as above.
pub fn nested_dissection_with_trailing(
    xadj: &[usize],
    adjncy: &[usize],
    trailing: &[bool],
) -> Result<(Vec<usize>, Vec<usize>), OrderingError> {
    let n = check_csr(xadj, adjncy)?;
    if trailing.len() != n {
        return Err(OrderingError::InvalidGraph(format!(
            "{} trailing marks for {n} vertices",
            trailing.len()
        )));
    }
    // The subgraph of the leading vertices, renumbered.
    let mut local = vec![usize::MAX; n];
    let leading: Vec<usize> = (0..n).filter(|&v| !trailing[v]).collect();
    for (i, &v) in leading.iter().enumerate() {
        local[v] = i;
    }
    let mut sx = Vec::with_capacity(leading.len() + 1);
    let mut sa = Vec::new();
    sx.push(0);
    for &v in &leading {
        sa.extend(
            adjncy[xadj[v]..xadj[v + 1]]
                .iter()
                .filter(|&&u| local[u] != usize::MAX)
                .map(|&u| local[u]),
        );
        sx.push(sa.len());
    }
    let (sub, _) = nested_dissection(&sx, &sa)?;
    let perm: Vec<usize> = sub
        .iter()
        .map(|&i| leading[i])
        .chain((0..n).filter(|&v| trailing[v]))
        .collect();
    let mut inv = vec![0; n];
    for (new, &old) in perm.iter().enumerate() {
        inv[old] = new;
    }
    Ok((perm, inv))
}

/// Node adjacency graph (CSR, symmetric, no self loops, no duplicates) of a symmetric
/// sparsity pattern stored as CSC (`col_ptr` of length `n + 1`, any triangle or both).
///
/// With `groups = Some(map)` (`map[dof] = node`, `n_nodes` nodes) two nodes are adjacent
/// when any of their DOFs couple, i.e. the quotient graph; with `None` the vertices are
/// the `n` DOFs themselves and `n_nodes` must be `n`. Returns `(xadj, adjncy)`.
pub fn graph_of_pattern(
    n: usize,
    col_ptr: &[usize],
    row_idx: &[usize],
    groups: Option<&[usize]>,
    n_nodes: usize,
) -> Result<(Vec<usize>, Vec<usize>), OrderingError> {
    let cols = check_csr(col_ptr, row_idx)?;
    if cols != n {
        return Err(OrderingError::InvalidGraph(format!(
            "col_ptr has {} entries for {n} columns",
            col_ptr.len()
        )));
    }
    let vertex_of = |dof: usize| groups.map_or(dof, |g| g[dof]);
    match groups {
        Some(g) => check_groups(g, n, n_nodes)?,
        None if n_nodes != n => {
            return Err(OrderingError::InvalidGroups(format!(
                "without groups the graph has {n} vertices, not {n_nodes}"
            )))
        }
        None => {}
    }
    // One pass builds, per vertex, the coupled vertices seen in its own columns (each
    // column's entries are scattered through a marker so every pair is kept once per
    // column group); `symmetrize` then adds the other direction.
    let members = group_members(n, n_nodes, &vertex_of);
    let mut marker = vec![usize::MAX; n_nodes];
    let mut hx = Vec::with_capacity(n_nodes + 1);
    let mut ha = Vec::new();
    hx.push(0);
    for (v, dofs) in members.1.windows(2).enumerate() {
        marker[v] = v;
        for &j in &members.0[dofs[0]..dofs[1]] {
            for &i in &row_idx[col_ptr[j]..col_ptr[j + 1]] {
                let u = vertex_of(i);
                if marker[u] != v {
                    marker[u] = v;
                    ha.push(u);
                }
            }
        }
        hx.push(ha.len());
    }
    Ok(symmetrize(n_nodes, &hx, &ha))
}

/// Expands a node ordering to a DOF ordering: the DOFs of each node follow each other
/// in the node's position, in ascending DOF order, whether or not they were consecutive
/// before. `node_perm[new] = old node`, `groups[dof] = node`; nodes without DOFs (fully
/// supported) are simply skipped. Returns `(perm, inv)` over DOFs.
pub fn expand_to_dofs(
    node_perm: &[usize],
    groups: &[usize],
) -> Result<(Vec<usize>, Vec<usize>), OrderingError> {
    let n_nodes = node_perm.len();
    let n = groups.len();
    check_groups(groups, n, n_nodes)?;
    let mut node_inv = vec![usize::MAX; n_nodes];
    for (new, &old) in node_perm.iter().enumerate() {
        if old >= n_nodes || node_inv[old] != usize::MAX {
            return Err(OrderingError::InvalidGroups(
                "node ordering is not a permutation".into(),
            ));
        }
        node_inv[old] = new;
    }
    // Counting sort of the DOFs by their node's new position keeps ascending DOF order
    // within a node because DOFs are visited in ascending order.
    let mut start = vec![0usize; n_nodes + 1];
    for &node in groups {
        start[node_inv[node] + 1] += 1;
    }
    for k in 0..n_nodes {
        start[k + 1] += start[k];
    }
    let mut perm = vec![0usize; n];
    for (dof, &node) in groups.iter().enumerate() {
        let slot = &mut start[node_inv[node]];
        perm[*slot] = dof;
        *slot += 1;
    }
    let mut inv = vec![0usize; n];
    for (new, &old) in perm.iter().enumerate() {
        inv[old] = new;
    }
    Ok((perm, inv))
}

/// The size of a Cholesky factor and the work of computing it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FactorCost {
    /// Entries of L's lower triangle, diagonal included.
    pub entries: usize,
    /// Σ over the factor's columns of (entries in the column)², the multiply-adds of a
    /// column-by-column factorization up to lower-order terms (for a dense block of w
    /// columns over p rows, w³/3 + w²p + wp² as the supernodal count has it).
    pub flops: f64,
}

/// Entries of the Cholesky factor's lower triangle (diagonal included) when the graph's
/// vertices are eliminated in the order `perm` (`perm[new] = old`, `inv[old] = new`) and
/// vertex `v` stands for a dense block of `sizes[v]` rows and columns (the DOFs of a node):
/// exact for a matrix whose coupled nodes couple in all their DOFs, an upper bound otherwise.
///
/// Column counts by row subtrees of the elimination tree (Liu), on the graph (symmetric,
/// as [`graph_of_pattern`] gives it) instead of the DOF pattern: 1/9 of the work for 3 DOFs
/// per node. Used to size the factor's buffer before the symbolic analysis.
pub fn factor_entries(
    xadj: &[usize],
    adjncy: &[usize],
    perm: &[usize],
    inv: &[usize],
    sizes: &[usize],
) -> usize {
    factor_cost(xadj, adjncy, perm, inv, sizes).entries
}

/// [`factor_entries`] and the factorization's flops ([`FactorCost`]) from the same column
/// counts: a node of `s` DOFs with `b` rows below its diagonal block has columns of
/// `b + s, b + s − 1, …, b + 1` entries.
pub fn factor_cost(
    xadj: &[usize],
    adjncy: &[usize],
    perm: &[usize],
    inv: &[usize],
    sizes: &[usize],
) -> FactorCost {
    const NONE: usize = usize::MAX;
    let n = perm.len();
    let mut parent = vec![NONE; n];
    let mut flag = vec![NONE; n];
    // Rows (DOFs) of each column block below its diagonal block.
    let mut below = vec![0usize; n];
    for k in 0..n {
        flag[k] = k;
        let v = perm[k];
        for &u in &adjncy[xadj[v]..xadj[v + 1]] {
            let mut i = inv[u];
            // Walk up from i to the root of its row subtree: each vertex met gains row k.
            while i < k && flag[i] != k {
                if parent[i] == NONE {
                    parent[i] = k;
                }
                below[i] += sizes[v];
                flag[i] = k;
                i = parent[i];
            }
        }
    }
    // Exact integer sums: the comparison of two orderings does not depend on rounding order.
    let (mut entries, mut flops) = (0usize, 0u128);
    for k in 0..n {
        let (s, b) = (sizes[perm[k]], below[k]);
        entries += s * (s + 1) / 2 + s * b;
        flops += (1..=s).map(|c| ((b + c) as u128).pow(2)).sum::<u128>();
    }
    FactorCost {
        entries,
        flops: flops as f64,
    }
}

/// A nested dissection chosen among two by its factorization's flops.
#[derive(Debug, Clone, PartialEq)]
pub struct ChosenOrdering {
    /// `perm[new] = old` over the graph's vertices.
    pub perm: Vec<usize>,
    /// `inv[old] = new`.
    pub inv: Vec<usize>,
    /// The chosen ordering's factor.
    pub cost: FactorCost,
    /// The other ordering's factor.
    pub other: FactorCost,
    /// Whether the chosen one is the second ordering (else METIS's defaults).
    pub second_chosen: bool,
}

/// Nested dissections with METIS's defaults and with `second`, computed side by side (METIS
/// keeps its random generator per thread, so each is what it would be alone), and the one
/// whose factor ([`factor_cost`], vertex `v` a block of `sizes[v]` DOFs) takes fewer flops;
/// the defaults on a tie. The same graph gives the same choice on any thread count.
pub fn best_of_two_orderings(
    xadj: &[usize],
    adjncy: &[usize],
    sizes: &[usize],
    second: MetisOptions,
) -> Result<ChosenOrdering, OrderingError> {
    let order = |options: MetisOptions| {
        nested_dissection_with(xadj, adjncy, options).map(|(perm, inv)| {
            let cost = factor_cost(xadj, adjncy, &perm, &inv, sizes);
            (perm, inv, cost)
        })
    };
    let (first, other) = rayon::join(|| order(MetisOptions::default()), || order(second));
    let (p0, i0, c0) = first?;
    let (p1, i1, c1) = other?;
    Ok(if c1.flops < c0.flops {
        ChosenOrdering {
            perm: p1,
            inv: i1,
            cost: c1,
            other: c0,
            second_chosen: true,
        }
    } else {
        ChosenOrdering {
            perm: p0,
            inv: i0,
            cost: c0,
            other: c1,
            second_chosen: false,
        }
    })
}

/// A graph METIS may safely read: symmetric, no self loops or duplicate edges, offsets
/// and indices valid, all in METIS's index type. Only [`MetisGraph::new`] builds one.
struct MetisGraph {
    xadj: Vec<idx_t>,
    adjncy: Vec<idx_t>,
}

impl MetisGraph {
    /// Cleans a checked CSR graph (see [`check_csr`]) and converts it to `idx_t`.
    fn new(n: usize, xadj: &[usize], adjncy: &[usize]) -> Result<Self, OrderingError> {
        idx_t::try_from(n).map_err(|_| too_large("vertices", n))?;
        let (sx, sa) = symmetrize(n, xadj, adjncy);
        Ok(Self {
            xadj: to_idx(&sx, "adjacency entries")?,
            adjncy: to_idx(&sa, "vertices")?,
        })
    }
}

/// Calls `METIS_NodeND` with `options` and returns its `(perm, iperm)`.
///
/// This is the crate's only `unsafe`. Its soundness rests on [`MetisGraph`]: METIS does
/// not validate its input, so it only ever sees a graph built by `MetisGraph::new`.
/// Calls may run side by side: the METIS built here (third_party/metis-sys) keeps its random
/// generator per thread, re-seeded at each call, so each ordering is the one it is alone.
fn metis_node_nd(
    graph: &mut MetisGraph,
    options: MetisOptions,
) -> Result<(Vec<idx_t>, Vec<idx_t>), OrderingError> {
    let n = graph.xadj.len() - 1;
    let mut nvtxs = idx_t::try_from(n).map_err(|_| too_large("vertices", n))?;
    let mut perm: Vec<idx_t> = vec![0; n];
    let mut iperm: Vec<idx_t> = vec![0; n];
    // METIS's defaults by a null pointer, as before options existed (the same ordering).
    let mut metis_options = (options != MetisOptions::default()).then(|| {
        let mut o: Vec<idx_t> = vec![-1; metis_sys::METIS_NOPTIONS as usize];
        o[metis_sys::moptions_et_METIS_OPTION_NUMBERING as usize] = 0;
        if let Some(seed) = options.seed {
            o[metis_sys::moptions_et_METIS_OPTION_SEED as usize] = seed;
        }
        if let Some(ufactor) = options.ufactor {
            o[metis_sys::moptions_et_METIS_OPTION_UFACTOR as usize] = ufactor;
        }
        o
    });
    let options_ptr = metis_options
        .as_mut()
        .map_or(std::ptr::null_mut(), |o| o.as_mut_ptr());
    // SAFETY: `nvtxs` is the vertex count, `xadj` has `nvtxs + 1` offsets ending at
    // `adjncy.len()`, every neighbour is a valid vertex and the graph is symmetric
    // without self loops (all by construction of `MetisGraph`); `perm` and `iperm` hold
    // `nvtxs` entries each; a null `vwgt` selects unit weights; `options` is null (METIS's
    // defaults) or METIS_NOPTIONS entries, −1 (default) but for 0-based numbering and the
    // values asked for. METIS keeps no pointer after returning.
    let status = unsafe {
        metis_sys::METIS_NodeND(
            &mut nvtxs,
            graph.xadj.as_mut_ptr(),
            graph.adjncy.as_mut_ptr(),
            std::ptr::null_mut(),
            options_ptr,
            perm.as_mut_ptr(),
            iperm.as_mut_ptr(),
        )
    };
    if status == metis_sys::rstatus_et_METIS_OK {
        Ok((perm, iperm))
    } else {
        let meaning = match status {
            metis_sys::rstatus_et_METIS_ERROR_INPUT => "erroneous input",
            metis_sys::rstatus_et_METIS_ERROR_MEMORY => "out of memory",
            _ => "internal error",
        };
        Err(OrderingError::Metis { status, meaning })
    }
}

fn too_large(what: &'static str, value: usize) -> OrderingError {
    OrderingError::TooLarge {
        what,
        value,
        bits: idx_t::BITS,
    }
}

fn to_idx(v: &[usize], what: &'static str) -> Result<Vec<idx_t>, OrderingError> {
    // The largest entry decides; the conversion below can then not wrap.
    let max = v.iter().copied().max().unwrap_or(0);
    if idx_t::try_from(max).is_err() {
        return Err(too_large(what, max));
    }
    Ok(v.iter().map(|&x| x as idx_t).collect())
}

/// Checks CSR/CSC offsets and indices and returns the number of rows (vertices).
fn check_csr(ptr: &[usize], idx: &[usize]) -> Result<usize, OrderingError> {
    let Some(n) = ptr.len().checked_sub(1) else {
        return Err(OrderingError::InvalidGraph(
            "offset array is empty (need n + 1 entries)".into(),
        ));
    };
    if ptr[0] != 0 || ptr[n] != idx.len() {
        return Err(OrderingError::InvalidGraph(format!(
            "offsets must run from 0 to {} (found {} to {})",
            idx.len(),
            ptr[0],
            ptr[n]
        )));
    }
    if let Some(v) = ptr.windows(2).position(|w| w[0] > w[1]) {
        return Err(OrderingError::InvalidGraph(format!(
            "offsets decrease at vertex {v}"
        )));
    }
    if let Some(&bad) = idx.iter().find(|&&i| i >= n) {
        return Err(OrderingError::InvalidGraph(format!(
            "index {bad} out of range for {n} vertices"
        )));
    }
    Ok(n)
}

fn check_groups(groups: &[usize], n: usize, n_nodes: usize) -> Result<(), OrderingError> {
    if groups.len() != n {
        return Err(OrderingError::InvalidGroups(format!(
            "{} group entries for {n} DOFs",
            groups.len()
        )));
    }
    if let Some(dof) = groups.iter().position(|&g| g >= n_nodes) {
        return Err(OrderingError::InvalidGroups(format!(
            "DOF {dof} belongs to node {} of {n_nodes}",
            groups[dof]
        )));
    }
    Ok(())
}

/// The DOFs of each vertex as CSR (`(dofs, offsets)`), DOFs ascending within a vertex.
fn group_members(
    n: usize,
    n_nodes: usize,
    vertex_of: &impl Fn(usize) -> usize,
) -> (Vec<usize>, Vec<usize>) {
    let mut start = vec![0usize; n_nodes + 1];
    for dof in 0..n {
        start[vertex_of(dof) + 1] += 1;
    }
    for k in 0..n_nodes {
        start[k + 1] += start[k];
    }
    let mut next = start.clone();
    let mut dofs = vec![0usize; n];
    for dof in 0..n {
        let slot = &mut next[vertex_of(dof)];
        dofs[*slot] = dof;
        *slot += 1;
    }
    (dofs, start)
}

/// Union of a graph and its transpose, without self loops and duplicate edges
/// (neighbour lists come out in no particular order). Indices must be valid.
fn symmetrize(n: usize, xadj: &[usize], adjncy: &[usize]) -> (Vec<usize>, Vec<usize>) {
    let mut deg = vec![0usize; n + 1];
    for v in 0..n {
        for &u in &adjncy[xadj[v]..xadj[v + 1]] {
            if u != v {
                deg[u + 1] += 1;
                deg[v + 1] += 1;
            }
        }
    }
    for k in 0..n {
        deg[k + 1] += deg[k];
    }
    let mut next = deg.clone();
    let mut both = vec![0usize; deg[n]];
    for v in 0..n {
        for &u in &adjncy[xadj[v]..xadj[v + 1]] {
            if u != v {
                both[next[v]] = u;
                next[v] += 1;
                both[next[u]] = v;
                next[u] += 1;
            }
        }
    }
    // Compact in place: the write cursor never passes the read cursor.
    let mut marker = vec![usize::MAX; n];
    let mut out_ptr = Vec::with_capacity(n + 1);
    out_ptr.push(0);
    let mut w = 0;
    for v in 0..n {
        for r in deg[v]..deg[v + 1] {
            let u = both[r];
            if marker[u] != v {
                marker[u] = v;
                both[w] = u;
                w += 1;
            }
        }
        out_ptr.push(w);
    }
    both.truncate(w);
    (out_ptr, both)
}

fn is_inverse_pair(perm: &[usize], inv: &[usize]) -> bool {
    perm.len() == inv.len()
        && perm
            .iter()
            .enumerate()
            .all(|(new, &old)| old < inv.len() && inv[old] == new)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 4-neighbour grid graph of nx × ny vertices.
    fn grid(nx: usize, ny: usize) -> (Vec<usize>, Vec<usize>) {
        let mut xadj = vec![0];
        let mut adj = Vec::new();
        for y in 0..ny {
            for x in 0..nx {
                if x > 0 {
                    adj.push(y * nx + x - 1);
                }
                if x + 1 < nx {
                    adj.push(y * nx + x + 1);
                }
                if y > 0 {
                    adj.push((y - 1) * nx + x);
                }
                if y + 1 < ny {
                    adj.push((y + 1) * nx + x);
                }
                xadj.push(adj.len());
            }
        }
        (xadj, adj)
    }

    fn assert_perm_pair(perm: &[usize], inv: &[usize], n: usize) {
        assert_eq!(perm.len(), n);
        let mut seen = vec![false; n];
        for &p in perm {
            assert!(!seen[p]);
            seen[p] = true;
        }
        assert!(is_inverse_pair(perm, inv));
    }

    #[test]
    fn metis_node_nd_orders_a_grid() {
        let (xadj, adj) = grid(7, 5);
        let mut graph = MetisGraph::new(35, &xadj, &adj).unwrap();
        let (perm, iperm) = metis_node_nd(&mut graph, MetisOptions::default()).unwrap();
        let perm: Vec<usize> = perm.iter().map(|&p| p as usize).collect();
        let iperm: Vec<usize> = iperm.iter().map(|&p| p as usize).collect();
        assert_perm_pair(&perm, &iperm, 35);
        // METIS must leave the graph as it found it (0-based numbering in and out).
        assert_eq!(graph.xadj.len(), 36);
        assert_eq!(graph.xadj[35] as usize, adj.len());
    }

    #[test]
    fn nested_dissection_of_grid_is_a_permutation() {
        let (xadj, adj) = grid(20, 13);
        let (perm, inv) = nested_dissection(&xadj, &adj).unwrap();
        assert_perm_pair(&perm, &inv, 260);
        // Nested dissection puts a separator last: it is not the identity.
        assert_ne!(perm, (0..260).collect::<Vec<_>>());
    }

    #[test]
    fn nested_dissection_trivial_cases() {
        assert_eq!(nested_dissection(&[0], &[]).unwrap(), (vec![], vec![]));
        assert_eq!(nested_dissection(&[0, 0], &[]).unwrap(), (vec![0], vec![0]));
        let (p, i) = nested_dissection(&[0, 0, 0, 0], &[]).unwrap();
        assert_eq!((p, i), (vec![0, 1, 2], vec![0, 1, 2]));
        // Only a self loop: no edges after cleaning.
        let (p, _) = nested_dissection(&[0, 1, 1], &[0]).unwrap();
        assert_eq!(p, vec![0, 1]);
    }

    #[test]
    fn nested_dissection_rejects_bad_graphs() {
        assert!(matches!(
            nested_dissection(&[], &[]),
            Err(OrderingError::InvalidGraph(_))
        ));
        assert!(matches!(
            nested_dissection(&[0, 1, 2], &[1, 5]),
            Err(OrderingError::InvalidGraph(_))
        ));
        assert!(matches!(
            nested_dissection(&[0, 2, 1], &[1, 0]),
            Err(OrderingError::InvalidGraph(_))
        ));
    }

    #[test]
    fn one_sided_graph_is_symmetrized() {
        // Path 0-1-2-3-4 given in one direction only, with a duplicate.
        let (xadj, adj) = (vec![0, 2, 3, 4, 5, 5], vec![1, 1, 2, 3, 4]);
        let (sx, sa) = symmetrize(5, &xadj, &adj);
        let mut rows: Vec<Vec<usize>> = (0..5).map(|v| sa[sx[v]..sx[v + 1]].to_vec()).collect();
        rows.iter_mut().for_each(|r| r.sort_unstable());
        assert_eq!(
            rows,
            vec![vec![1], vec![0, 2], vec![1, 3], vec![2, 4], vec![3]]
        );
        let (perm, inv) = nested_dissection(&xadj, &adj).unwrap();
        assert_perm_pair(&perm, &inv, 5);
    }

    #[test]
    fn factor_entries_by_hand() {
        // Path 0-1-2-3 in natural order: no fill, 4 + 3 entries with one DOF per vertex;
        // with 3 DOFs per vertex 4 × 6 (diagonal blocks) + 3 × 9 (coupling blocks).
        let (x, a) = (vec![0, 1, 3, 5, 6], vec![1, 0, 2, 1, 3, 2]);
        let id = [0, 1, 2, 3];
        assert_eq!(factor_entries(&x, &a, &id, &id, &[1; 4]), 7);
        assert_eq!(factor_entries(&x, &a, &id, &id, &[3; 4]), 4 * 6 + 3 * 9);
        // Star with its centre 0 eliminated first: the leaves fill into a clique,
        // 4 diagonal + 3 (column 0) + 2 + 1 entries.
        let (x, a) = (vec![0, 3, 4, 5, 6], vec![1, 2, 3, 0, 0, 0]);
        assert_eq!(factor_entries(&x, &a, &id, &id, &[1; 4]), 10);
        // Centre last: no fill, 4 + 3 entries; sizes 2 at the centre, 1 elsewhere: 3 + 3 + 3 × 2.
        let (perm, inv) = ([1, 2, 3, 0], [3, 0, 1, 2]);
        assert_eq!(factor_entries(&x, &a, &perm, &inv, &[1; 4]), 7);
        assert_eq!(
            factor_entries(&x, &a, &perm, &inv, &[2, 1, 1, 1]),
            3 + 3 + 6
        );
    }

    extern "C" {
        // GKlib's generator as METIS calls it (third_party/metis-sys/vendor/GKlib/random.c).
        fn gk_randinit(seed: u64);
        fn gk_randint32() -> u32;
    }

    /// METIS's per-thread generator draws glibc's `rand()` (= `random()`) sequence after `srand(seed)`, so
    /// every ordering is bitwise the one METIS gave with libc's process-wide generator.
    #[test]
    fn metis_generator_is_glibcs_rand() {
        for seed in [0u32, 1, 4321, 12345, 0x8000_0005, u32::MAX] {
            // SAFETY: GKlib's generator only touches this thread's state; glibc's
            // srand/rand (= srandom/random) lock their state and nothing else here draws from it.
            let (ours, glibc): (Vec<u32>, Vec<u32>) = unsafe {
                gk_randinit(u64::from(seed));
                libc::srand(seed);
                (0..10_000)
                    .map(|_| (gk_randint32(), libc::rand() as u32))
                    .unzip()
            };
            assert_eq!(ours, glibc, "seed {seed}");
        }
    }

    /// The process's SIGTERM handler, as `sigaction` reports it.
    fn sigterm_handler() -> libc::sighandler_t {
        // SAFETY: a null new action only reads the current one into `old`.
        let mut old: libc::sigaction = unsafe { std::mem::zeroed() };
        let r = unsafe { libc::sigaction(libc::SIGTERM, std::ptr::null(), &mut old) };
        assert_eq!(r, 0);
        old.sa_sigaction
    }

    #[test]
    fn metis_leaves_the_sigterm_handler_alone_on_two_threads() {
        // Upstream GKlib installs a longjmp handler for SIGTERM during every METIS call (and,
        // with two calls at once, can leave it installed): a SIGTERM then jumps through an
        // empty buffer (a segmentation fault). The handler must be the same throughout.
        let before = sigterm_handler();
        let (xadj, adj) = lattice_graph(12, 12, 12);
        let done = std::sync::atomic::AtomicBool::new(false);
        let mut seen = 0usize;
        std::thread::scope(|s| {
            for _ in 0..2 {
                s.spawn(|| {
                    for _ in 0..6 {
                        nested_dissection(&xadj, &adj).unwrap();
                    }
                    done.store(true, std::sync::atomic::Ordering::SeqCst);
                });
            }
            while !done.load(std::sync::atomic::Ordering::SeqCst) {
                assert_eq!(sigterm_handler(), before, "changed while METIS ran");
                seen += 1;
            }
        });
        assert_eq!(sigterm_handler(), before, "changed after METIS ran");
        assert!(seen > 10, "sampled {seen} times");
    }

    /// Node graph of an nx × ny × nz lattice whose nodes join their 26 neighbours.
    fn lattice_graph(nx: usize, ny: usize, nz: usize) -> (Vec<usize>, Vec<usize>) {
        let id = |x: usize, y: usize, z: usize| (z * ny + y) * nx + x;
        let mut xadj = vec![0];
        let mut adj = Vec::new();
        for z in 0..nz {
            for y in 0..ny {
                for x in 0..nx {
                    for (dx, dy, dz) in (0..27).map(|k| (k % 3, k / 3 % 3, k / 9)) {
                        let (u, v, w) = (
                            (x + dx).wrapping_sub(1),
                            (y + dy).wrapping_sub(1),
                            (z + dz).wrapping_sub(1),
                        );
                        if (dx, dy, dz) != (1, 1, 1) && u < nx && v < ny && w < nz {
                            adj.push(id(u, v, w));
                        }
                    }
                    xadj.push(adj.len());
                }
            }
        }
        (xadj, adj)
    }

    /// Four threads ordering four different graphs at once, several times, get each graph's
    /// ordering alone (before the per-thread generator they interleaved one libc state).
    #[test]
    fn orderings_side_by_side_are_the_sequential_ones() {
        let graphs = [
            lattice_graph(14, 12, 11),
            lattice_graph(9, 17, 13),
            lattice_graph(20, 10, 8),
            lattice_graph(12, 12, 12),
        ];
        let options = [
            MetisOptions::default(),
            SECOND_ORDERING,
            MetisOptions::default(),
            MetisOptions {
                seed: Some(7),
                ufactor: Some(50),
            },
        ];
        let alone: Vec<_> = graphs
            .iter()
            .zip(options)
            .map(|((x, a), o)| nested_dissection_with(x, a, o).unwrap())
            .collect();
        for _ in 0..4 {
            let together: Vec<_> = std::thread::scope(|scope| {
                let handles: Vec<_> = graphs
                    .iter()
                    .zip(options)
                    .map(|((x, a), o)| scope.spawn(move || nested_dissection_with(x, a, o)))
                    .collect();
                handles
                    .into_iter()
                    .map(|h| h.join().unwrap().unwrap())
                    .collect()
            });
            assert_eq!(together, alone);
        }
        // The options reach METIS: another seed gives another ordering of the same graph.
        let (x, a) = &graphs[0];
        assert_ne!(
            nested_dissection_with(x, a, SECOND_ORDERING).unwrap(),
            nested_dissection(x, a).unwrap()
        );
    }

    #[test]
    fn factor_cost_by_hand() {
        // Path 0-1-2-3, one DOF per vertex, natural order: columns of 2, 2, 2, 1 entries.
        let (x, a) = (vec![0, 1, 3, 5, 6], vec![1, 0, 2, 1, 3, 2]);
        let id = [0, 1, 2, 3];
        let c = factor_cost(&x, &a, &id, &id, &[1; 4]);
        assert_eq!((c.entries, c.flops), (7, 13.0));
        // Two DOFs per vertex: a vertex with b rows below has columns of b + 2 and b + 1.
        // Three vertices with b = 2 (16 + 9 each), the last with b = 0 (4 + 1).
        let c = factor_cost(&x, &a, &id, &id, &[2; 4]);
        assert_eq!((c.entries, c.flops), (4 * 3 + 3 * 4, 3.0 * 25.0 + 5.0));
        // Star with its centre first: the leaves fill into a clique, columns of 4, 3, 2, 1.
        let (x, a) = (vec![0, 3, 4, 5, 6], vec![1, 2, 3, 0, 0, 0]);
        let c = factor_cost(&x, &a, &id, &id, &[1; 4]);
        assert_eq!((c.entries, c.flops), (10, 30.0));
    }

    /// The choice is the ordering with fewer flops, the same on repeated calls, and its cost
    /// is that ordering's own.
    #[test]
    fn best_of_two_takes_the_cheaper_ordering() {
        let (x, a) = lattice_graph(14, 12, 11);
        let sizes = vec![3; 14 * 12 * 11];
        let chosen = best_of_two_orderings(&x, &a, &sizes, SECOND_ORDERING).unwrap();
        let (p0, i0) = nested_dissection(&x, &a).unwrap();
        let (p1, i1) = nested_dissection_with(&x, &a, SECOND_ORDERING).unwrap();
        let (c0, c1) = (
            factor_cost(&x, &a, &p0, &i0, &sizes),
            factor_cost(&x, &a, &p1, &i1, &sizes),
        );
        assert_ne!(c0.flops, c1.flops, "pick a graph where the two differ");
        let (expected, cost, other) = if c1.flops < c0.flops {
            (p1, c1, c0)
        } else {
            (p0, c0, c1)
        };
        assert_eq!(chosen.perm, expected);
        assert_eq!(chosen.second_chosen, c1.flops < c0.flops);
        assert_eq!((chosen.cost, chosen.other), (cost, other));
        assert!(is_inverse_pair(&chosen.perm, &chosen.inv));
        assert_eq!(
            best_of_two_orderings(&x, &a, &sizes, SECOND_ORDERING).unwrap(),
            chosen
        );
        // The same options twice: a tie, and the defaults win it.
        let tie = best_of_two_orderings(&x, &a, &sizes, MetisOptions::default()).unwrap();
        assert!(!tie.second_chosen);
        assert_eq!(tie.cost, tie.other);
    }

    #[test]
    fn expansion_keeps_node_dofs_together() {
        // 4 nodes, node 2 fully supported (no DOFs); DOFs of node 0 interleaved.
        let groups = [0, 1, 0, 3, 3, 1, 0];
        let node_perm = [3, 0, 2, 1];
        let (perm, inv) = expand_to_dofs(&node_perm, &groups).unwrap();
        assert_perm_pair(&perm, &inv, 7);
        assert_eq!(perm, vec![3, 4, 0, 2, 6, 1, 5]);
        assert!(expand_to_dofs(&[0, 0], &[0, 1]).is_err());
        assert!(expand_to_dofs(&[0, 1], &[0, 2]).is_err());
    }

    #[test]
    fn quotient_graph_of_lower_pattern() {
        // 3 nodes × 2 DOFs on a path: node blocks (0,1)-(2,3)-(4,5), lower triangle.
        let cols: Vec<Vec<usize>> = vec![
            vec![0, 1, 2, 3],
            vec![1, 2, 3],
            vec![2, 3, 4, 5],
            vec![3, 4, 5],
            vec![4, 5],
            vec![5],
        ];
        let mut col_ptr = vec![0];
        let mut row_idx = Vec::new();
        for c in &cols {
            row_idx.extend_from_slice(c);
            col_ptr.push(row_idx.len());
        }
        let groups = [0, 0, 1, 1, 2, 2];
        let (x, a) = graph_of_pattern(6, &col_ptr, &row_idx, Some(&groups), 3).unwrap();
        let mut rows: Vec<Vec<usize>> = (0..3).map(|v| a[x[v]..x[v + 1]].to_vec()).collect();
        rows.iter_mut().for_each(|r| r.sort_unstable());
        assert_eq!(rows, vec![vec![1], vec![0, 2], vec![1]]);
        let (x, a) = graph_of_pattern(6, &col_ptr, &row_idx, None, 6).unwrap();
        assert_eq!(x.len(), 7);
        assert_eq!(a.len(), 2 * (row_idx.len() - 6));
    }
}
