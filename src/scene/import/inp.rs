//! Abaqus/CalculiX input files (`.inp`) as a body: `*NODE`, `*ELEMENT` (T2D2, T3D2),
//! `*NSET`/`*ELSET` (lists, set names or `GENERATE`), `*MATERIAL` with `*ELASTIC` and
//! `*DENSITY`, `*SOLID SECTION` (the area on its data line), `*BOUNDARY`, `*CLOAD`, one
//! `*STEP` with `*STATIC`, `*INCLUDE`. Keywords and names are case-insensitive; any other
//! keyword is reported once as ignored, with its line. Values are taken as SI (m, N, Pa, kg/m³).

use crate::linkage::{Dimension, Geometry};
use crate::scene::import::inp_lines::{read_cards, Card, Place};
use crate::scene::import::{ImportedModel, ModelFileError, ModelMaterial, ModelSupport, NodeGroup};
use crate::Real;
use nalgebra::Vector3;
use std::collections::HashMap;
use std::path::Path;

/// An element as read: its id, node ids and line.
struct Element {
    id: i64,
    nodes: [i64; 2],
    place: Place,
}

/// A `*MATERIAL` with what its sub-keywords gave.
struct InpMaterial {
    name: String,
    youngs_modulus: Option<Real>,
    density: Option<Real>,
}

/// A `*SOLID SECTION`: element set, material and area.
struct Section {
    elset: String,
    material: String,
    area: Real,
    place: Place,
}

/// A named set: upper-case key, name as written, members (node or element ids).
struct Set {
    key: String,
    name: String,
    ids: Vec<i64>,
}

/// Everything read from the cards, before numbering.
#[derive(Default)]
struct Deck {
    nodes: Vec<Vector3<Real>>,
    node_ids: Vec<i64>,
    node_index: HashMap<i64, usize>,
    elements: Vec<Element>,
    element_index: HashMap<i64, usize>,
    dimension: Option<(Dimension, Place)>,
    nsets: Vec<Set>,
    elsets: Vec<Set>,
    materials: Vec<InpMaterial>,
    sections: Vec<Section>,
    /// `(place, node id, first DOF, last DOF, value)`.
    boundaries: Vec<(Place, i64, usize, usize, Real)>,
    /// `(place, node id, DOF, force)`.
    loads: Vec<(Place, i64, usize, Real)>,
    steps: usize,
    /// Ignored keywords: name, first place, count.
    ignored: Vec<(String, Place, usize)>,
    warnings: Vec<String>,
}

/// A whole number field.
fn integer(place: &Place, field: &str, what: &str) -> Result<i64, ModelFileError> {
    field
        .parse::<i64>()
        .map_err(|_| place.error(format!("{what} is {field:?}: give a whole number")))
}

/// A finite number field (Fortran `D` exponents accepted).
fn number(place: &Place, field: &str, what: &str) -> Result<Real, ModelFileError> {
    field
        .replace(['d', 'D'], "e")
        .parse::<Real>()
        .ok()
        .filter(|v| v.is_finite())
        .ok_or_else(|| place.error(format!("{what} is {field:?}: give a finite number")))
}

/// The field `k` of a data line, or an error naming what is missing.
fn field<'a>(
    place: &Place,
    fields: &'a [String],
    k: usize,
    what: &str,
) -> Result<&'a str, ModelFileError> {
    fields
        .get(k)
        .map(String::as_str)
        .filter(|f| !f.is_empty())
        .ok_or_else(|| place.error(format!("the line has no {what} (field {})", k + 1)))
}

impl Deck {
    /// The set `name` (case-insensitive) among `sets`.
    fn set<'a>(sets: &'a [Set], name: &str) -> Option<&'a Set> {
        let key = name.to_uppercase();
        sets.iter().find(|s| s.key == key)
    }

    /// The ids a set's data lines list: numbers, names of sets already defined, or
    /// `first, last, increment` with `GENERATE`.
    fn set_ids(card: &Card, sets: &[Set], kind: &str) -> Result<Vec<i64>, ModelFileError> {
        let mut ids = Vec::new();
        for (place, fields) in &card.data {
            if card.has("GENERATE") {
                let first = integer(place, field(place, fields, 0, "first id")?, "the first id")?;
                let last = integer(place, field(place, fields, 1, "last id")?, "the last id")?;
                let step = match fields.get(2) {
                    Some(f) if !f.is_empty() => integer(place, f, "the increment")?,
                    _ => 1,
                };
                let span = last.checked_sub(first);
                if step <= 0 || span.is_none_or(|s| s < 0 || s / step > 10_000_000) {
                    return Err(place.error(format!(
                        "GENERATE {first}, {last}, {step}: give first ≤ last and an increment of 1 or more"
                    )));
                }
                ids.extend((first..=last).step_by(step as usize));
                continue;
            }
            for f in fields.iter().filter(|f| !f.is_empty()) {
                match f.parse::<i64>() {
                    Ok(id) => ids.push(id),
                    Err(_) => match Self::set(sets, f) {
                        Some(s) => ids.extend(&s.ids),
                        None => {
                            return Err(place.error(format!(
                                "{f:?} is neither a {kind} number nor a {kind} set defined above"
                            )))
                        }
                    },
                }
            }
        }
        Ok(ids)
    }

    /// Add `ids` to the set `name` of `sets` (created if new).
    fn add_to(sets: &mut Vec<Set>, name: &str, ids: Vec<i64>) {
        let key = name.to_uppercase();
        match sets.iter_mut().find(|s| s.key == key) {
            Some(s) => s.ids.extend(ids),
            None => sets.push(Set {
                key,
                name: name.to_string(),
                ids,
            }),
        }
    }

    /// The node ids a `*BOUNDARY` or `*CLOAD` target names: a node number or a node set.
    fn targets(&self, place: &Place, target: &str) -> Result<Vec<i64>, ModelFileError> {
        if let Ok(id) = target.parse::<i64>() {
            return Ok(vec![id]);
        }
        Self::set(&self.nsets, target)
            .map(|s| s.ids.clone())
            .ok_or_else(|| {
                place.error(format!(
                    "{target:?} is neither a node number nor a node set (*NSET) defined above"
                ))
            })
    }

    fn read(&mut self, card: &Card) -> Result<(), ModelFileError> {
        match card.keyword.as_str() {
            "NODE" => {
                let mut ids = Vec::new();
                for (place, fields) in &card.data {
                    let id = integer(
                        place,
                        field(place, fields, 0, "node number")?,
                        "the node number",
                    )?;
                    if fields.len() > 4 {
                        return Err(place.error(format!(
                            "node {id} has {} coordinates: give x, y and optionally z",
                            fields.len() - 1
                        )));
                    }
                    let mut p = Vector3::zeros();
                    for k in 0..3 {
                        if let Some(f) = fields.get(k + 1).filter(|f| !f.is_empty()) {
                            p[k] =
                                number(place, f, &format!("{} of node {id}", ["x", "y", "z"][k]))?;
                        }
                    }
                    if self.node_index.insert(id, self.nodes.len()).is_some() {
                        return Err(place.error(format!(
                            "node {id} is defined twice: give each node its own number"
                        )));
                    }
                    self.nodes.push(p);
                    self.node_ids.push(id);
                    ids.push(id);
                }
                if let Some(name) = card.param("NSET") {
                    Self::add_to(&mut self.nsets, name, ids);
                }
            }
            "ELEMENT" => {
                let kind = card.required("TYPE")?.to_uppercase();
                let dimension = match kind.as_str() {
                    "T3D2" => Dimension::Three,
                    "T2D2" => Dimension::Two,
                    other => {
                        let what = match other.chars().next() {
                            Some('B') => "a beam, which carries bending",
                            Some('S') => "a shell",
                            Some('C') => "a continuum element",
                            _ => "not a two-node truss",
                        };
                        return Err(card.place.error(format!(
                            "element type {other} is {what}: linkage members carry axial force only; use T3D2 (3D truss) or T2D2 (2D truss) elements"
                        )));
                    }
                };
                match &self.dimension {
                    Some((d, first)) if *d != dimension => {
                        return Err(card.place.error(format!(
                            "*ELEMENT, TYPE={kind} mixes 2D and 3D trusses with the elements at {}: a body is one or the other",
                            first.describe()
                        )))
                    }
                    Some(_) => {}
                    None => self.dimension = Some((dimension, card.place.clone())),
                }
                let mut ids = Vec::new();
                for (place, fields) in &card.data {
                    let id = integer(
                        place,
                        field(place, fields, 0, "element number")?,
                        "the element number",
                    )?;
                    if fields.len() != 3 {
                        return Err(place.error(format!("element {id} of type {kind} needs its number and 2 nodes; the line has {} fields", fields.len())));
                    }
                    let a = integer(place, &fields[1], "a node number")?;
                    let b = integer(place, &fields[2], "a node number")?;
                    if self.element_index.insert(id, self.elements.len()).is_some() {
                        return Err(place.error(format!(
                            "element {id} is defined twice: give each element its own number"
                        )));
                    }
                    self.elements.push(Element {
                        id,
                        nodes: [a, b],
                        place: place.clone(),
                    });
                    ids.push(id);
                }
                if let Some(name) = card.param("ELSET") {
                    Self::add_to(&mut self.elsets, name, ids);
                }
            }
            "NSET" => {
                let name = card.required("NSET")?;
                let mut ids = Self::set_ids(card, &self.nsets, "node")?;
                if let Some(elset) = card.param("ELSET") {
                    let set = Self::set(&self.elsets, elset).ok_or_else(|| {
                        card.place.error(format!(
                            "ELSET={elset:?} is not an element set defined above"
                        ))
                    })?;
                    for id in &set.ids {
                        if let Some(&e) = self.element_index.get(id) {
                            ids.extend(self.elements[e].nodes);
                        }
                    }
                }
                Self::add_to(&mut self.nsets, name, ids);
            }
            "ELSET" => {
                let name = card.required("ELSET")?;
                let ids = Self::set_ids(card, &self.elsets, "element")?;
                Self::add_to(&mut self.elsets, name, ids);
            }
            "MATERIAL" => {
                let name = card.required("NAME")?;
                if self
                    .materials
                    .iter()
                    .any(|m| m.name.eq_ignore_ascii_case(name))
                {
                    return Err(card
                        .place
                        .error(format!("*MATERIAL {name} is defined twice")));
                }
                self.materials.push(InpMaterial {
                    name: name.to_string(),
                    youngs_modulus: None,
                    density: None,
                });
            }
            "ELASTIC" | "DENSITY" => {
                let Some(material) = self.materials.last_mut() else {
                    return Err(card.place.error(format!(
                        "*{} before any *MATERIAL: put it under the *MATERIAL it belongs to",
                        card.keyword
                    )));
                };
                if let Some(t) = card
                    .param("TYPE")
                    .filter(|t| !t.eq_ignore_ascii_case("ISOTROPIC"))
                {
                    return Err(card.place.error(format!("*ELASTIC, TYPE={t}: a member has one Young's modulus; give TYPE=ISOTROPIC (E, ν)")));
                }
                let Some((place, fields)) = card.data.first() else {
                    return Err(card.place.error(format!(
                        "*{} has no data line: give its value on the next line",
                        card.keyword
                    )));
                };
                let value = number(
                    place,
                    field(place, fields, 0, "value")?,
                    if card.keyword == "ELASTIC" {
                        "Young's modulus"
                    } else {
                        "the density"
                    },
                )?;
                if card.data.len() > 1 {
                    self.warnings.push(format!(
                        "{}: *{} has {} data lines (values by temperature): the first is used",
                        card.place.describe(),
                        card.keyword,
                        card.data.len()
                    ));
                }
                if card.keyword == "ELASTIC" {
                    material.youngs_modulus = Some(value);
                } else {
                    material.density = Some(value);
                }
            }
            "SOLID SECTION" => {
                let elset = card.required("ELSET")?.to_string();
                let material = card.required("MATERIAL")?.to_string();
                let Some((place, fields)) = card.data.first() else {
                    return Err(card.place.error("*SOLID SECTION of a truss needs its cross-section area (m²) on the next line"));
                };
                let area = number(
                    place,
                    field(place, fields, 0, "cross-section area")?,
                    "the cross-section area",
                )?;
                self.sections.push(Section {
                    elset,
                    material,
                    area,
                    place: card.place.clone(),
                });
            }
            "BOUNDARY" => {
                for (place, fields) in &card.data {
                    let target = field(place, fields, 0, "node or node set")?;
                    let first = field(place, fields, 1, "first degree of freedom")?;
                    let (first, last, value) = match first.to_uppercase().as_str() {
                        "ENCASTRE" | "PINNED" => (1, 3, 0.0),
                        "XSYMM" => (1, 1, 0.0),
                        "YSYMM" => (2, 2, 0.0),
                        "ZSYMM" => (3, 3, 0.0),
                        _ => {
                            let first = integer(place, first, "the first degree of freedom")?;
                            let last = match fields.get(2).filter(|f| !f.is_empty()) {
                                Some(f) => integer(place, f, "the last degree of freedom")?,
                                None => first,
                            };
                            let value = match fields.get(3).filter(|f| !f.is_empty()) {
                                Some(f) => number(place, f, "the prescribed displacement")?,
                                None => 0.0,
                            };
                            if !(1..=6).contains(&first) || last < first || last > 6 {
                                return Err(place.error(format!("degrees of freedom {first} to {last}: give 1 to 3 (x, y, z; 4 to 6 are rotations, which a truss node has not)")));
                            }
                            (first as usize, last as usize, value)
                        }
                    };
                    for id in self.targets(place, target)? {
                        self.boundaries
                            .push((place.clone(), id, first, last, value));
                    }
                }
            }
            "CLOAD" => {
                for (place, fields) in &card.data {
                    let target = field(place, fields, 0, "node or node set")?;
                    let dof = integer(
                        place,
                        field(place, fields, 1, "degree of freedom")?,
                        "the degree of freedom",
                    )?;
                    let value = number(place, field(place, fields, 2, "magnitude")?, "the load")?;
                    if !(1..=3).contains(&dof) {
                        return Err(place.error(format!("*CLOAD in degree of freedom {dof}: a truss node takes forces in 1 to 3 (x, y, z), no moments")));
                    }
                    for id in self.targets(place, target)? {
                        self.loads.push((place.clone(), id, dof as usize, value));
                    }
                }
            }
            "STEP" => {
                self.steps += 1;
                if self.steps > 1 {
                    return Err(card.place.error("a second *STEP: linkage reads one static step; put each step's loads in its own model (or scene)"));
                }
                if card.has("NLGEOM")
                    && !card
                        .param("NLGEOM")
                        .is_some_and(|v| v.eq_ignore_ascii_case("NO"))
                {
                    self.warnings.push(format!("{}: *STEP, NLGEOM is not read: give kinematics = \"large\" in the scene for large displacements", card.place.describe()));
                }
            }
            "STATIC" | "END STEP" | "HEADING" => {}
            "DYNAMIC"
            | "FREQUENCY"
            | "BUCKLE"
            | "MODAL DYNAMIC"
            | "HEAT TRANSFER"
            | "VISCO"
            | "COUPLED TEMPERATURE-DISPLACEMENT" => {
                return Err(card.place.error(format!(
                    "*{}: linkage solves one *STATIC step; change the procedure to *STATIC",
                    card.keyword
                )));
            }
            other => match self.ignored.iter_mut().find(|(k, _, _)| k == other) {
                Some(entry) => entry.2 += 1,
                None => self
                    .ignored
                    .push((other.to_string(), card.place.clone(), 1)),
            },
        }
        Ok(())
    }
}

/// Read an Abaqus/CalculiX input file (with its `*INCLUDE`s) as a body.
pub fn read_inp(path: &Path) -> Result<ImportedModel, ModelFileError> {
    let cards = read_cards(path)?;
    let mut deck = Deck::default();
    for card in &cards {
        deck.read(card)?;
    }
    model_of_deck(path, deck)
}

fn model_of_deck(path: &Path, deck: Deck) -> Result<ImportedModel, ModelFileError> {
    let Some((dimension, _)) = deck.dimension.clone() else {
        return Err(ModelFileError::at(
            path,
            1,
            "the file has no *ELEMENT: give the members as *ELEMENT, TYPE=T3D2 (or T2D2)",
        ));
    };
    // Nodes the elements use, in file order.
    let mut used = vec![false; deck.nodes.len()];
    let mut ends = Vec::with_capacity(deck.elements.len());
    for e in &deck.elements {
        let mut pair = [0; 2];
        for (k, id) in e.nodes.iter().enumerate() {
            let &n = deck.node_index.get(id).ok_or_else(|| {
                e.place.error(format!(
                    "element {} names node {id}, which no *NODE defines",
                    e.id
                ))
            })?;
            used[n] = true;
            pair[k] = n;
        }
        if pair[0] == pair[1] {
            return Err(e.place.error(format!(
                "element {} joins node {} to itself: give two different nodes",
                e.id, e.nodes[0]
            )));
        }
        ends.push(pair);
    }
    let mut index = vec![usize::MAX; deck.nodes.len()];
    let mut nodes = Vec::new();
    for (n, &u) in used.iter().enumerate() {
        if u {
            index[n] = nodes.len();
            nodes.push(deck.nodes[n]);
        }
    }
    if dimension == Dimension::Two {
        if let Some(n) = nodes.iter().position(|p| p.z != 0.0) {
            let id = deck.node_ids[index.iter().position(|&i| i == n).unwrap_or(0)];
            return Err(ModelFileError::at(path, 1, format!("node {id} has z = {} but the elements are T2D2 (2D): give 2D nodes or use T3D2", nodes[n].z)));
        }
    }
    // The body's node of an INP node id, or an error at `place`.
    let node_of = |place: &Place, id: i64| -> Result<usize, ModelFileError> {
        match deck.node_index.get(&id) {
            None => Err(place.error(format!("node {id} is not defined by any *NODE"))),
            Some(&n) if index[n] == usize::MAX => Err(place.error(format!(
                "node {id} belongs to no element: it is not part of the body"
            ))),
            Some(&n) => Ok(index[n]),
        }
    };
    let d = dimension.dofs_per_node();
    let mut members = Vec::with_capacity(ends.len());
    for pair in &ends {
        members.push(pair.map(|n| index[n]));
    }
    // Sections: each element's (material, area).
    let mut member_section: Vec<Option<usize>> = vec![None; members.len()];
    for (s, section) in deck.sections.iter().enumerate() {
        let set = Deck::set(&deck.elsets, &section.elset).ok_or_else(|| {
            section.place.error(format!(
                "*SOLID SECTION, ELSET={}: no such element set (*ELEMENT, ELSET=... or *ELSET)",
                section.elset
            ))
        })?;
        for id in &set.ids {
            let &e = deck.element_index.get(id).ok_or_else(|| {
                section.place.error(format!(
                    "element set {} lists element {id}, which no *ELEMENT defines",
                    set.name
                ))
            })?;
            if let Some(other) = member_section[e] {
                return Err(section.place.error(format!(
                    "element {id} is in this section and in the one at {}: give each element one section",
                    deck.sections[other].place.describe()
                )));
            }
            member_section[e] = Some(s);
        }
    }
    // One material per distinct (material, area).
    let mut materials: Vec<ModelMaterial> = Vec::new();
    let mut of_section = vec![usize::MAX; deck.sections.len()];
    let one_word = |name: &str| {
        name.split_whitespace()
            .collect::<Vec<_>>()
            .join("_")
            .replace([',', '#'], "_")
    };
    for (s, section) in deck.sections.iter().enumerate() {
        let m = deck
            .materials
            .iter()
            .find(|m| m.name.eq_ignore_ascii_case(&section.material))
            .ok_or_else(|| {
                section.place.error(format!(
                    "MATERIAL={}: no *MATERIAL, NAME={} is defined",
                    section.material, section.material
                ))
            })?;
        let youngs_modulus = m.youngs_modulus.ok_or_else(|| {
            section.place.error(format!(
                "material {} has no *ELASTIC: give its Young's modulus",
                m.name
            ))
        })?;
        let areas: Vec<Real> = deck
            .sections
            .iter()
            .filter(|o| o.material.eq_ignore_ascii_case(&m.name))
            .map(|o| o.area)
            .collect();
        let name = if areas.iter().all(|&a| a == section.area) {
            one_word(&m.name)
        } else {
            let set = Deck::set(&deck.elsets, &section.elset)
                .map_or(section.elset.as_str(), |s| s.name.as_str());
            format!("{}_{}", one_word(&m.name), one_word(set))
        };
        of_section[s] = match materials.iter().position(|o| o.name == name) {
            Some(k) => k,
            None => {
                materials.push(ModelMaterial {
                    name,
                    youngs_modulus,
                    area: section.area,
                    density: m.density,
                });
                materials.len() - 1
            }
        };
    }
    let unassigned = member_section.iter().position(Option::is_none).map(|e| {
        let element = &deck.elements[e];
        format!("{}: element {} has no *SOLID SECTION: add one (ELSET=..., MATERIAL=..., its area on the next line) or name a scene material with `material =`", element.place.describe(), element.id)
    });
    let member_materials: Vec<Option<usize>> = if deck.sections.is_empty() {
        Vec::new()
    } else {
        member_section
            .iter()
            .map(|s| s.map(|s| of_section[s]))
            .collect()
    };
    // Supports per node.
    let mut held: Vec<Option<([bool; 3], Vector3<Real>)>> = vec![None; nodes.len()];
    let mut rotations = None;
    for (place, id, first, last, value) in &deck.boundaries {
        let n = node_of(place, *id)?;
        let entry = held[n].get_or_insert(([false; 3], Vector3::zeros()));
        for dof in *first..=*last {
            if dof > d {
                if dof <= 3 && *value != 0.0 {
                    return Err(place.error(format!(
                        "a displacement of {value} in z but the body is 2D (T2D2)"
                    )));
                }
                rotations.get_or_insert_with(|| place.describe());
                continue;
            }
            entry.0[dof - 1] = true;
            entry.1[dof - 1] = *value;
        }
    }
    let mut warnings = deck.warnings;
    if let Some(at) = rotations {
        warnings.push(format!("{at}: *BOUNDARY on degrees of freedom a truss node has not (rotations 4 to 6, or z of a 2D body) is ignored"));
    }
    for (keyword, place, count) in &deck.ignored {
        let more = if *count > 1 {
            format!(" (and {} more times)", count - 1)
        } else {
            String::new()
        };
        warnings.push(format!(
            "{}: *{keyword} is ignored{more}: linkage does not read it",
            place.describe()
        ));
    }
    let supports = held
        .iter()
        .enumerate()
        .filter_map(|(node, h)| {
            h.map(|(fixed, displacement)| ModelSupport {
                node,
                fixed,
                displacement,
            })
        })
        .collect();
    let mut force = vec![Vector3::zeros(); nodes.len()];
    for (place, id, dof, value) in &deck.loads {
        let n = node_of(place, *id)?;
        if *dof > d {
            if *value != 0.0 {
                return Err(
                    place.error(format!("a load of {value} in z but the body is 2D (T2D2)"))
                );
            }
            continue;
        }
        force[n][dof - 1] += value;
    }
    let loads = force
        .into_iter()
        .enumerate()
        .filter(|(_, f)| *f != Vector3::zeros())
        .collect();
    // Groups: node sets, then element sets by the nodes of their elements.
    let mut groups: Vec<NodeGroup> = Vec::new();
    for set in &deck.nsets {
        let mut ids: Vec<usize> = set
            .ids
            .iter()
            .filter_map(|id| deck.node_index.get(id))
            .map(|&n| index[n])
            .filter(|&n| n != usize::MAX)
            .collect();
        ids.sort_unstable();
        ids.dedup();
        groups.push(NodeGroup {
            name: set.name.clone(),
            nodes: ids,
        });
    }
    for set in &deck.elsets {
        if groups
            .iter()
            .any(|g| g.name.eq_ignore_ascii_case(&set.name))
        {
            continue;
        }
        let mut ids: Vec<usize> = set
            .ids
            .iter()
            .filter_map(|id| deck.element_index.get(id))
            .flat_map(|&e| members[e])
            .collect();
        ids.sort_unstable();
        ids.dedup();
        groups.push(NodeGroup {
            name: set.name.clone(),
            nodes: ids,
        });
    }
    Ok(ImportedModel {
        geometry: Geometry {
            dimension,
            nodes,
            members,
            patches: Vec::new(),
        },
        groups,
        materials,
        member_materials,
        unassigned,
        supports,
        loads,
        warnings,
    })
}
