//! gmsh MSH 4.1 files, ASCII and binary: `$MeshFormat`, `$PhysicalNames`, `$Entities`,
//! `$Nodes` and `$Elements` (other sections are skipped).
//!
//! Our own reader rather than the `mshio` crate, on the merits: `mshio` (the one MSH 4.1
//! crate) skips `$PhysicalNames`, which is what turns a group called "clamp" into a support,
//! and its parse errors are nom's, without a line; the format's five sections take a few
//! hundred lines here, and every problem names the file and line (a binary section: its byte).

use crate::scene::import::msh_cursor::MshCursor;
use crate::scene::import::ModelFileError;
use crate::Real;
use nalgebra::Vector3;
use std::collections::HashMap;
use std::path::Path;

/// The kinds of element a body is made from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MshElementKind {
    /// Type 15: one node (only its groups are read).
    Point,
    /// Type 1: a 2-node line, a member.
    Line,
    /// Type 2: a 3-node triangle.
    Triangle,
    /// Type 4: a 4-node tetrahedron.
    Tetrahedron,
}

impl MshElementKind {
    /// The kind of gmsh element type `code` (`None`: not one a linkage is made from).
    fn of(code: i64) -> Option<Self> {
        match code {
            15 => Some(Self::Point),
            1 => Some(Self::Line),
            2 => Some(Self::Triangle),
            4 => Some(Self::Tetrahedron),
            _ => None,
        }
    }

    /// Nodes per element.
    pub fn nodes(self) -> usize {
        match self {
            Self::Point => 1,
            Self::Line => 2,
            Self::Triangle => 3,
            Self::Tetrahedron => 4,
        }
    }
}

/// One element of an MSH file.
#[derive(Clone, Debug, PartialEq)]
pub struct MshElement {
    /// Its kind.
    pub kind: MshElementKind,
    /// Its nodes, indices into [`MshMesh::nodes`].
    pub nodes: Vec<usize>,
    /// The physical groups of its entity, as `(dimension, physical tag)`.
    pub groups: Vec<(i64, i64)>,
    /// The line of its block's header, for messages.
    pub line: usize,
}

/// An MSH file as read.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MshMesh {
    /// Node positions, m, in file order.
    pub nodes: Vec<Vector3<Real>>,
    /// The gmsh tag of each node.
    pub node_tags: Vec<usize>,
    /// Elements in file order.
    pub elements: Vec<MshElement>,
    /// `$PhysicalNames`: `(dimension, tag, name)`.
    pub physical_names: Vec<(i64, i64, String)>,
}

/// The name of a gmsh element type code, for messages.
fn type_name(code: i64) -> &'static str {
    match code {
        3 => "4-node quadrangle",
        5 => "8-node hexahedron",
        6 => "6-node prism",
        7 => "5-node pyramid",
        8 => "3-node second-order line",
        9 => "6-node second-order triangle",
        10 => "9-node quadrangle",
        11 => "10-node second-order tetrahedron",
        _ => "element",
    }
}

/// Read an MSH 4.1 file (ASCII or binary).
pub fn read_msh(path: &Path) -> Result<MshMesh, ModelFileError> {
    let bytes = std::fs::read(path)
        .map_err(|e| ModelFileError::at(path, 0, format!("cannot read the gmsh file: {e}")))?;
    parse_msh(&bytes, path)
}

/// Parse the bytes of an MSH 4.1 file; `path` names it in errors.
pub fn parse_msh(bytes: &[u8], path: &Path) -> Result<MshMesh, ModelFileError> {
    let mut c = MshCursor {
        path,
        bytes,
        pos: 0,
        binary: false,
        section: "",
    };
    let mut mesh = MshMesh::default();
    let mut format_seen = false;
    // Physical tags of each entity, by (dimension, entity tag).
    let mut entity_groups: HashMap<(i64, i64), Vec<i64>> = HashMap::new();
    let mut tag_index: HashMap<usize, usize> = HashMap::new();
    let mut elements_seen = false;
    loop {
        let start = c.pos;
        let Some(line) = c.line() else { break };
        let header = line.trim();
        if header.is_empty() {
            continue;
        }
        if !header.starts_with('$') {
            c.pos = start;
            return Err(c.error(format!(
                "{:?} is outside any section: an MSH file is made of $Section ... $EndSection blocks",
                header.chars().take(40).collect::<String>()
            )));
        }
        if !format_seen && header != "$MeshFormat" {
            c.pos = start;
            return Err(c.error(
                "the file does not begin with $MeshFormat: it is not a gmsh MSH file (write it with gmsh, File > Export, Version 4.1)",
            ));
        }
        match header {
            "$MeshFormat" => {
                read_format(&mut c)?;
                format_seen = true;
            }
            "$PhysicalNames" => {
                c.section = "$PhysicalNames";
                mesh.physical_names = read_physical_names(&mut c)?;
            }
            "$Entities" => {
                c.section = "$Entities";
                entity_groups = read_entities(&mut c)?;
                c.end("$EndEntities")?;
            }
            "$Nodes" => {
                c.section = "$Nodes";
                read_nodes(&mut c, &mut mesh, &mut tag_index)?;
                c.end("$EndNodes")?;
            }
            "$Elements" => {
                c.section = "$Elements";
                read_elements(&mut c, &mut mesh, &tag_index, &entity_groups)?;
                c.end("$EndElements")?;
                elements_seen = true;
            }
            other => {
                // Another section ($Periodic, $NodeData, ...): skipped to its end.
                let end = format!("$End{}", &other[1..]);
                c.section = "";
                loop {
                    match c.line() {
                        Some(l) if l.trim() == end => break,
                        Some(_) => {}
                        None => {
                            return Err(c.error(format!(
                                "the file ends before {end}: the section {other} is not closed"
                            )))
                        }
                    }
                }
            }
        }
        c.section = "";
    }
    if !format_seen {
        return Err(ModelFileError::at(
            path,
            1,
            "the file is empty: a gmsh MSH file begins with $MeshFormat",
        ));
    }
    if !elements_seen || mesh.elements.is_empty() {
        return Err(c.error(
            "the file has no elements (no $Elements section, or an empty one): mesh the model in gmsh before saving",
        ));
    }
    Ok(mesh)
}

/// `$MeshFormat`: version 4.1, ASCII (0) or binary (1) with 8-byte `size_t` and, binary, the
/// integer 1 to check the byte order.
fn read_format(c: &mut MshCursor) -> Result<(), ModelFileError> {
    let at = c.pos;
    let line = c.line().unwrap_or("");
    let words: Vec<&str> = line.split_whitespace().collect();
    let bad = |c: &mut MshCursor, m: String| {
        c.pos = at;
        Err(c.error(m))
    };
    if words.len() != 3 {
        return bad(c, format!("$MeshFormat line {line:?}: expected \"4.1 0 8\" (version, file type, size of size_t)"));
    }
    if words[0] != "4.1" {
        return bad(c, format!(
            "MSH version {} is not read: save as version 4.1 (gmsh -format msh41, or the option Mesh.MshFileVersion = 4.1)",
            words[0]
        ));
    }
    match (words[1], words[2]) {
        ("0", _) => c.binary = false,
        ("1", "8") => c.binary = true,
        ("1", size) => {
            return bad(c, format!("a binary MSH file with {size}-byte size_t is not read: save it on a 64-bit machine, or as ASCII"))
        }
        (t, _) => return bad(c, format!("file type {t} is neither 0 (ASCII) nor 1 (binary)")),
    }
    if c.binary {
        c.section = "$MeshFormat";
        let one = c.int("the byte-order integer 1")?;
        if one != 1 {
            return Err(c.error(
                "the byte-order check is not 1: the binary file is big-endian or damaged; save it as ASCII",
            ));
        }
    }
    c.end("$EndMeshFormat")
}

/// `$PhysicalNames`: a count, then `dimension tag "name"` per line (text in binary files too).
fn read_physical_names(c: &mut MshCursor) -> Result<Vec<(i64, i64, String)>, ModelFileError> {
    let at = c.pos;
    let count_line = c.line().unwrap_or("");
    let count: usize = count_line.trim().parse().map_err(|_| {
        c.pos = at;
        c.error(format!(
            "{count_line:?} should be the number of physical names"
        ))
    })?;
    let mut names = Vec::new();
    for _ in 0..count {
        let at = c.pos;
        let Some(line) = c.line() else {
            return Err(c.error("the file ends inside $PhysicalNames: it is cut short"));
        };
        let mut parts = line.trim().splitn(3, char::is_whitespace);
        let (dim, tag, name) = (parts.next(), parts.next(), parts.next());
        let parsed = (|| {
            let dim: i64 = dim?.parse().ok()?;
            let tag: i64 = tag?.parse().ok()?;
            let name = name?.trim();
            let name = name.strip_prefix('"')?.strip_suffix('"')?;
            Some((dim, tag, name.to_string()))
        })();
        match parsed {
            Some(p) => names.push(p),
            None => {
                c.pos = at;
                return Err(c.error(format!(
                    "{line:?}: a physical name is `dimension tag \"name\"`"
                )));
            }
        }
    }
    c.end("$EndPhysicalNames")?;
    Ok(names)
}

/// `$Entities`: the physical tags of each point, curve, surface and volume.
fn read_entities(c: &mut MshCursor) -> Result<HashMap<(i64, i64), Vec<i64>>, ModelFileError> {
    let mut counts = [0usize; 4];
    for (dim, n) in counts.iter_mut().enumerate() {
        *n = c.size(
            [
                "the number of points",
                "the number of curves",
                "the number of surfaces",
                "the number of volumes",
            ][dim],
        )?;
    }
    let mut groups = HashMap::new();
    for (dim, &n) in counts.iter().enumerate() {
        for _ in 0..n {
            let tag = c.int("an entity tag")?;
            // A point has its position, the others a bounding box.
            for _ in 0..if dim == 0 { 3 } else { 6 } {
                c.double("an entity coordinate")?;
            }
            let physical = c.size("the number of physical tags")?;
            if physical > c.remaining() {
                return Err(c.error(format!(
                    "an entity has {physical} physical tags, more than the file holds"
                )));
            }
            let tags = (0..physical)
                .map(|_| c.int("a physical tag"))
                .collect::<Result<Vec<_>, _>>()?;
            if dim > 0 {
                let bounding = c.size("the number of bounding entities")?;
                if bounding > c.remaining() {
                    return Err(c.error(format!(
                        "an entity has {bounding} bounding entities, more than the file holds"
                    )));
                }
                for _ in 0..bounding {
                    c.int("a bounding entity tag")?;
                }
            }
            groups.insert((dim as i64, tag), tags);
        }
    }
    Ok(groups)
}

/// `$Nodes`: blocks of tags then coordinates (with parametric coordinates, skipped).
fn read_nodes(
    c: &mut MshCursor,
    mesh: &mut MshMesh,
    tag_index: &mut HashMap<usize, usize>,
) -> Result<(), ModelFileError> {
    let blocks = c.size("the number of node blocks")?;
    let total = c.size("the number of nodes")?;
    c.size("the smallest node tag")?;
    c.size("the largest node tag")?;
    if total > c.remaining() {
        return Err(c.error(format!(
            "the section announces {total} nodes, more than the file holds: it is cut short"
        )));
    }
    mesh.nodes.reserve(total);
    for _ in 0..blocks {
        let dim = c.int("the block's entity dimension")?;
        c.int("the block's entity tag")?;
        let parametric = c.int("the block's parametric flag")?;
        let n = c.size("the number of nodes in the block")?;
        if n > c.remaining() {
            return Err(c.error(format!(
                "a node block announces {n} nodes, more than the file holds: it is cut short"
            )));
        }
        let mut tags = Vec::with_capacity(n);
        for _ in 0..n {
            let at = c.pos;
            let tag = c.size("a node tag")?;
            if tag_index.contains_key(&tag) {
                c.pos = at;
                return Err(c.error(format!(
                    "node tag {tag} appears twice: each node needs its own tag"
                )));
            }
            tag_index.insert(tag, mesh.nodes.len() + tags.len());
            tags.push(tag);
        }
        let extra = if parametric != 0 {
            dim.clamp(0, 3) as usize
        } else {
            0
        };
        for &tag in &tags {
            let mut p = Vector3::zeros();
            for k in 0..3 {
                p[k] = c.double(&format!("coordinate {} of node {tag}", ["x", "y", "z"][k]))?;
            }
            for _ in 0..extra {
                c.double("a parametric coordinate")?;
            }
            mesh.nodes.push(p);
        }
        mesh.node_tags.extend(tags);
    }
    if mesh.nodes.len() != total {
        return Err(c.error(format!(
            "the blocks hold {} nodes but the section announces {total}",
            mesh.nodes.len()
        )));
    }
    Ok(())
}

/// `$Elements`: blocks of one type on one entity, each element its tag and nodes.
fn read_elements(
    c: &mut MshCursor,
    mesh: &mut MshMesh,
    tag_index: &HashMap<usize, usize>,
    entity_groups: &HashMap<(i64, i64), Vec<i64>>,
) -> Result<(), ModelFileError> {
    let blocks = c.size("the number of element blocks")?;
    let total = c.size("the number of elements")?;
    c.size("the smallest element tag")?;
    c.size("the largest element tag")?;
    let mut read = 0;
    for _ in 0..blocks {
        c.skip_space();
        let header = c.pos;
        let dim = c.int("the block's entity dimension")?;
        let entity = c.int("the block's entity tag")?;
        let code = c.int("the block's element type")?;
        let n = c.size("the number of elements in the block")?;
        let Some(kind) = MshElementKind::of(code) else {
            c.pos = header;
            return Err(c.error(format!(
                "element type {code} ({}) is not read: a linkage is made from first-order lines (1), triangles (2) and tetrahedra (4); mesh with those (Mesh.ElementOrder = 1, no recombination)",
                type_name(code)
            )));
        };
        if n > c.remaining() {
            return Err(c.error(format!("an element block announces {n} elements, more than the file holds: it is cut short")));
        }
        let groups: Vec<(i64, i64)> = entity_groups
            .get(&(dim, entity))
            .map(|tags| tags.iter().map(|&t| (dim, t.abs())).collect())
            .unwrap_or_default();
        let line = c.line_of(header);
        for _ in 0..n {
            let tag = c.size("an element tag")?;
            let mut nodes = Vec::with_capacity(kind.nodes());
            for _ in 0..kind.nodes() {
                let at = c.pos;
                let node = c.size(&format!("a node of element {tag}"))?;
                let Some(&index) = tag_index.get(&node) else {
                    c.pos = at;
                    return Err(c.error(format!(
                        "element {tag} names node {node}, which $Nodes does not define (or $Nodes comes after $Elements)"
                    )));
                };
                if nodes.contains(&index) {
                    c.pos = at;
                    return Err(c.error(format!(
                        "element {tag} names node {node} twice: a degenerate element; remesh"
                    )));
                }
                nodes.push(index);
            }
            mesh.elements.push(MshElement {
                kind,
                nodes,
                groups: groups.clone(),
                line,
            });
        }
        read += n;
    }
    if read != total {
        return Err(c.error(format!(
            "the blocks hold {read} elements but the section announces {total}"
        )));
    }
    Ok(())
}
