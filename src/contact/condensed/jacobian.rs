//! The condensed contact problem's Jacobian: one row per active contact, factored once and reused while Newton converges with it.

use crate::contact::condensed::CondensedBody;
use crate::contact::FrictionKey;
use crate::Real;
use faer::linalg::solvers::Solve;
use faer::{Accum, Mat, MatMut, MatRef, Par, Side};
use nalgebra::{Matrix3, Vector3};
use rayon::prelude::*;
use std::cell::Cell;
use std::collections::HashMap;

/// One row of the condensed problem: an active contact's normal (or, with friction, one of
/// its tangent directions): its stiffness (N/m) and its row of `G`, the relative motion along
/// the direction per unit displacement, as (body, candidate slot, coefficient).
pub(crate) struct ContactRow {
    /// Stiffness of the row against its own motion, N/m: the penalty of a normal row; with
    /// friction, the stiffness while the contact sticks (`k_n` along its normal, `k_t` along
    /// a tangent).
    pub penalty: Real,
    /// The row's nonzero entries, as (body, candidate slot, coefficient).
    pub entries: Vec<(usize, usize, Real)>,
    /// With friction: the contact the row belongs to (`None`: a frictionless normal row).
    pub friction: Option<FrictionRow>,
}

/// A row of a contact with friction: the contact's rows, the row's direction and the
/// contact's stiffness while it slips.
#[derive(Clone, Copy)]
pub(crate) struct FrictionRow {
    /// The contact's first row (its rows are consecutive: the normal, then the tangents).
    pub first: usize,
    /// The contact's number of rows.
    pub count: usize,
    /// The row's direction (unit).
    pub axis: Vector3<Real>,
    /// While the contact slips, its stiffness `−∂f/∂g` (N/m, Cartesian, unsymmetric);
    /// `None` while it sticks (then `k_n n nᵀ + k_t P`: the rows' penalties, uncoupled).
    pub slipping: Option<Matrix3<Real>>,
    /// The contact's friction history key: a factor kept across contact sets finds the
    /// contact's rows by it (see [`ContactJacobian::adopt`]).
    pub contact: Option<FrictionKey>,
}

/// `(κ⁻¹ + G C Gᵀ)⁻¹ x`, applied as `(I + κ G C Gᵀ)⁻¹ κ x` (κ may be singular while a
/// contact slips): a Cholesky factor without friction, [`FrictionInverse`] with it.
enum Inverse {
    Symmetric(faer::linalg::solvers::Llt<Real>),
    Friction(Box<FrictionInverse>),
}

impl Inverse {
    /// The friction inverse when it is not exact (see [`reference_stiffness`]).
    fn approximate(&self) -> Option<&FrictionInverse> {
        match self {
            Inverse::Friction(f) if !f.exact => Some(f),
            _ => None,
        }
    }

    fn solve_in_place(&self, x: MatMut<'_, Real>) {
        match self {
            Inverse::Symmetric(llt) => llt.solve_in_place(x),
            Inverse::Friction(f) => f.solve_in_place(x),
        }
    }
}

/// `(I + κ A)⁻¹ κ` for contacts with friction, `A = G C Gᵀ` and `κ` block-diagonal (one block
/// per contact, over its normal and tangent rows).
///
/// `F = A + R⁻¹` (symmetric positive definite) is factored once by Cholesky, of the size of
/// the rows, with `R` the diagonal reference of each row at factorization
/// ([`reference_stiffness`]: exact for a sticking contact, the symmetric diagonal of the
/// tangent for a slipping one). A contact whose state differs from the one it had at
/// factorization has a block `K` (unsymmetric) other than `R`: its rows (the set `S`) are solved
/// exactly by a Schur complement; contacts slipping then and now keep their reference (a
/// modified Newton step in the slip tangent's coupling and size, as in `G`; the residual stays
/// exact, so the converged state is the exact law's). With `w = F y` the rows outside `S` give
/// `w_T = x_T`; those in `S` give
///
/// `[(I − K R⁻¹) Z + K] w_S = K x_S − (I − K R⁻¹) y⁰_S`, `Z = (F⁻¹)_SS`, `y⁰ = F⁻¹ [x_T; 0]`,
///
/// and then `y = F⁻¹ w`. `Z = Xᵀ X` with `X = L⁻¹ E_S` (`F = L Lᵀ`), whose columns are kept:
/// when contacts start or stop slipping only the new rows' columns and the small dense
/// problem on `S` are formed again, not `F` (see [`ContactJacobian::restiffen`]).
struct FrictionInverse {
    llt: Factor,
    /// Rows of contacts that left the contact set since the factorization (a factor kept
    /// across sets): solved as rows of zero stiffness, exactly, through the Schur complement.
    gone: Vec<bool>,
    /// `R` per row, N/m.
    reference: Vec<Real>,
    /// Whether each row's contact slipped at factorization (never when `exact`).
    reference_slips: Vec<bool>,
    /// Whether every slipping contact is solved exactly (the stick stiffnesses as reference).
    exact: bool,
    /// The rows of contacts whose state differs from the one at factorization, ascending.
    slipping: Vec<usize>,
    /// `K` on those rows: per row, (position in `slipping`, N/m).
    kappa: Vec<Vec<(usize, Real)>>,
    /// LU of `(I − K R⁻¹) Z + K` (`None` while nothing slips).
    schur: Option<faer::linalg::solvers::PartialPivLu<Real>>,
    /// Columns `L⁻¹ e_j` by row `j`, kept with the factor.
    columns: HashMap<usize, Vec<Real>>,
    /// `Z = Xᵀ X` on `slipping` as last formed (`None` when none is, or the factor changed
    /// since): the same rows in `S` take it again, only `K` and the small LU are new.
    z: Option<Mat<Real>>,
}

/// The Cholesky factor `F = L Lᵀ` of a [`FrictionInverse`]: faer's as made, or a lower
/// triangle of its own once rows were bordered in (see [`FrictionInverse::border`]).
enum Factor {
    Faer(faer::linalg::solvers::Llt<Real>),
    Bordered(Mat<Real>),
}

impl Factor {
    /// `L` (its lower triangle; the solves read nothing above it).
    fn l(&self) -> MatRef<'_, Real> {
        match self {
            Factor::Faer(llt) => llt.L(),
            Factor::Bordered(l) => l.as_ref(),
        }
    }

    /// `x ← F⁻¹ x`.
    fn solve_in_place(&self, mut x: MatMut<'_, Real>) {
        match self {
            Factor::Faer(llt) => llt.solve_in_place(x),
            Factor::Bordered(l) => {
                use faer::linalg::triangular_solve as tri;
                tri::solve_lower_triangular_in_place(l.as_ref(), x.as_mut(), Par::rayon(0));
                tri::solve_upper_triangular_in_place(l.transpose(), x, Par::rayon(0));
            }
        }
    }
}

/// Right-hand sides solved together when columns of `L⁻¹` are formed.
const COLUMN_BLOCK: usize = 64;

/// A kept Jacobian with friction takes new states by a Schur complement while at most one row
/// in this many belongs to a contact whose state changed since the factorization.
const MOST_CHANGED: usize = 8;

/// The reference stiffness of a slipping contact's row along its slip direction, relative to
/// the row's stick stiffness: the exact tangent has none there (the force is μ f_N whatever
/// the slip); a small positive value keeps `F = A + R⁻¹` finite and positive definite while
/// making the row nearly free, as the slip leaves it.
const SLIP_REFERENCE: Real = 1e-6;

/// The diagonal stiffness `R` of each row that [`FrictionInverse`] factors `A + R⁻¹` with,
/// N/m: a frictionless row's penalty; a sticking contact's `k_n` and `k_t`; a slipping
/// contact's diagonal of its tangent in the row's own axes (`k_n` along the normal, about
/// nothing along the slip, `μ f_N k_t / |f*|` across it when the rows follow the slip), its
/// unsymmetric coupling `μ k_n t nᵀ` left out. The rows' states at factorization are thereby
/// part of the factor: only contacts that change state later need the Schur complement.
/// With `exact`, every row's stick stiffness (its penalty): every slipping contact then goes
/// through the Schur complement, an exact Newton step in the friction law.
fn reference_stiffness(rows: &[ContactRow], exact: bool) -> Vec<Real> {
    rows.iter()
        .map(
            |r| match r.friction.and_then(|f| f.slipping.map(|k| (f, k))) {
                Some(_) if exact => r.penalty,
                Some((f, k)) => (f.axis.dot(&(k * f.axis))).max(SLIP_REFERENCE * r.penalty),
                None => r.penalty,
            },
        )
        .collect()
}

/// The stiffness block of a contact's row `i` against its row `j`, both of `rows` (N/m, in
/// their own axes): the exact tangent of the contact's state.
fn exact_stiffness(rows: &[ContactRow], i: usize, j: usize) -> Real {
    let (Some(a), Some(b)) = (rows[i].friction, rows[j].friction) else {
        return if i == j { rows[i].penalty } else { 0.0 };
    };
    match a.slipping {
        Some(k3) => a.axis.dot(&(k3 * b.axis)),
        None if i == j => rows[i].penalty,
        None => 0.0,
    }
}

/// Contact rows from which a Jacobian with friction takes the slipping contacts' tangents
/// approximately (see [`FrictionInverse`]) when more than a quarter of the rows slip. Below,
/// or with fewer slipping, each slipping contact's exact tangent costs little; the pair of
/// 21,952-node boxes has 4,386-4,680 rows.
pub(crate) const APPROXIMATE_FROM: usize = 2000;

/// Whether at most a quarter of `rows` belong to slipping contacts.
pub(crate) fn few_slip(rows: &[ContactRow]) -> bool {
    4 * rows.iter().filter(|r| slips(r)).count() <= rows.len()
}

thread_local! {
    /// This thread's [`approximate_from`]: [`APPROXIMATE_FROM`] unless a test lowers it to
    /// drive the large-set mode through the solver on a small pair.
    static APPROXIMATE_FROM_HERE: Cell<usize> = const { Cell::new(APPROXIMATE_FROM) };
}

/// Contact rows from which the large-set mode applies on this thread: the approximate factor
/// when more than a quarter of the rows slip, slipping rows along their slip, and with the
/// approximate factor Anderson mixing and early letting-go of held contacts (see `solver.rs`).
pub(crate) fn approximate_from() -> usize {
    APPROXIMATE_FROM_HERE.with(Cell::get)
}

#[cfg(test)]
thread_local! {
    /// How often a kept Jacobian took another contact set's rows on this thread (contacts
    /// bordered in or gone; see [`ContactJacobian::adopt`]).
    static CARRIED: Cell<usize> = const { Cell::new(0) };
}

/// How often a kept Jacobian took another contact set on this thread since the last call.
#[cfg(test)]
pub(crate) fn take_carried() -> usize {
    CARRIED.with(|c| c.replace(0))
}

/// Set this thread's [`approximate_from`] (tests only; the default is [`APPROXIMATE_FROM`]).
#[cfg(test)]
pub(crate) fn set_approximate_from(rows: usize) {
    APPROXIMATE_FROM_HERE.with(|c| c.set(rows));
}

/// Whether a Jacobian with friction for `rows` should take every slipping contact's tangent
/// exactly: few rows or few slipping.
pub(crate) fn exact_for(rows: &[ContactRow]) -> bool {
    rows.len() < approximate_from() || few_slip(rows)
}

/// Whether a row's contact slips (a frictionless row: no).
fn slips(r: &ContactRow) -> bool {
    r.friction.is_some_and(|f| f.slipping.is_some())
}

impl FrictionInverse {
    /// Factor `F` (`f`, `A + R⁻¹` with `R` the rows' [`reference_stiffness`], `exact` or not)
    /// and take the rows' stiffnesses.
    fn new(f: Mat<Real>, rows: &[ContactRow], exact: bool) -> Result<Self, String> {
        // The frictionless path finds `κ⁻¹ + G C Gᵀ` not positive definite where the
        // candidates' compliance is not (then the coupled solve takes over): the same test
        // here, with the stick stiffnesses.
        let llt = f
            .llt(Side::Lower)
            .map_err(|e| format!("the contact matrix is not positive definite: {e:?}"))?;
        let mut inverse = FrictionInverse {
            llt: Factor::Faer(llt),
            gone: vec![false; rows.len()],
            reference: reference_stiffness(rows, exact),
            reference_slips: rows.iter().map(|r| slips(r) && !exact).collect(),
            exact,
            slipping: Vec::new(),
            kappa: Vec::new(),
            schur: None,
            columns: HashMap::new(),
            z: None,
        };
        inverse.set_stiffness(rows);
        Ok(inverse)
    }

    /// Take the blocks of the contacts of `rows` whose state differs from the one at
    /// factorization (turned into the rows' own axes) and form the Schur complement on their
    /// rows.
    ///
    /// Returns whether the inverse changed: `false` when the rows in `S` and their `K` are
    /// those it already has (a Jacobian taking the same states again at a later iterate),
    /// so that nothing is formed again, not even what depends on the inverse.
    fn set_stiffness(&mut self, rows: &[ContactRow]) -> bool {
        let k = rows.len();
        let slipping: Vec<usize> = rows
            .iter()
            .enumerate()
            .filter(|&(i, r)| self.gone[i] || slips(r) != self.reference_slips[i])
            .map(|(i, _)| i)
            .collect();
        let s = slipping.len();
        let mut position = vec![usize::MAX; k];
        for (p, &i) in slipping.iter().enumerate() {
            position[i] = p;
        }
        let kappa: Vec<Vec<(usize, Real)>> = slipping
            .iter()
            .map(|&i| {
                // A row gone from the contact set has no stiffness: its force is zero.
                let Some(f) = rows[i].friction.filter(|_| !self.gone[i]) else {
                    return Vec::new();
                };
                // A contact's rows change state together, so they are all in `S`.
                (f.first..f.first + f.count)
                    .map(|j| (position[j], exact_stiffness(rows, i, j)))
                    .filter(|&(p, v)| p != usize::MAX && v != 0.0)
                    .collect()
            })
            .collect();
        // `Z` depends only on the factor and on which rows are in `S`; the Schur complement
        // on `K` too: the same rows and `K` give the same inverse, bit for bit.
        let same_rows = self.z.is_some() && slipping == self.slipping;
        if same_rows && kappa == self.kappa {
            return false;
        }
        self.slipping = slipping;
        self.kappa = kappa;
        if s == 0 {
            self.schur = None;
            self.z = Some(Mat::zeros(0, 0));
            return true;
        }
        let z = match self.z.take().filter(|_| same_rows) {
            Some(z) => z,
            None => self.form_z(k),
        };
        // (I − K R⁻¹) Z + K, K block-diagonal.
        let mut schur = z.clone();
        for (p, row) in self.kappa.iter().enumerate() {
            for &(q, v) in row {
                let c = v / self.reference[self.slipping[q]];
                for j in 0..s {
                    schur[(p, j)] -= c * z[(q, j)];
                }
                schur[(p, q)] += v;
            }
        }
        self.schur = Some(schur.partial_piv_lu());
        self.z = Some(z);
        true
    }

    /// `Z = Xᵀ X` on the rows in `slipping`, `X = L⁻¹ E_S` (the columns not kept yet formed).
    fn form_z(&mut self, k: usize) -> Mat<Real> {
        let s = self.slipping.len();
        // The columns of L⁻¹ not formed yet, in blocks from the first row of each (the
        // forward solve of e_j is zero above j).
        let l = self.llt.l();
        let mut missing: Vec<usize> = self
            .slipping
            .iter()
            .copied()
            .filter(|j| !self.columns.contains_key(j))
            .collect();
        missing.sort_unstable();
        for block in missing.chunks(COLUMN_BLOCK) {
            let j0 = block[0];
            let mut rhs = Mat::<Real>::zeros(k - j0, block.len());
            for (q, &j) in block.iter().enumerate() {
                rhs[(j - j0, q)] = 1.0;
            }
            faer::linalg::triangular_solve::solve_lower_triangular_in_place(
                l.submatrix(j0, j0, k - j0, k - j0),
                rhs.as_mut(),
                Par::rayon(0),
            );
            for (q, &j) in block.iter().enumerate() {
                let mut column = vec![0.0; k];
                for i in j0..k {
                    column[i] = rhs[(i - j0, q)];
                }
                self.columns.insert(j, column);
            }
        }
        let mut x = Mat::<Real>::zeros(k, s);
        for (p, j) in self.slipping.iter().enumerate() {
            if let Some(column) = self.columns.get(j) {
                for (i, &v) in column.iter().enumerate() {
                    x[(i, p)] = v;
                }
            }
        }
        let mut z = Mat::<Real>::zeros(s, s);
        faer::linalg::matmul::matmul(
            z.as_mut(),
            Accum::Replace,
            x.transpose(),
            x.as_ref(),
            1.0,
            Par::rayon(0),
        );
        z
    }

    fn solve_in_place(&self, mut x: MatMut<'_, Real>) {
        if self.reference.len() >= approximate_from() && self.solve_split(x.as_mut()) {
            return;
        }
        self.solve_twice(x);
    }

    /// The solve of [`FrictionInverse`] with one forward and one backward solve by `L` (the
    /// large-set mode's; [`FrictionInverse::solve_twice`]'s arithmetic below it):
    /// `v = L⁻¹ [x_T; 0]`, `y⁰_S = Xᵀ v`, then `y = L⁻ᵀ (v + X w_S)`, as
    /// `F⁻¹ E_S = L⁻ᵀ X`. `false`, and `x` untouched, when there is no Schur complement or
    /// a column of `X` is missing.
    fn solve_split(&self, mut x: MatMut<'_, Real>) -> bool {
        use faer::linalg::triangular_solve as tri;
        let Some(schur) = &self.schur else {
            return false;
        };
        let columns: Option<Vec<&Vec<Real>>> =
            self.slipping.iter().map(|j| self.columns.get(j)).collect();
        let Some(columns) = columns else {
            return false;
        };
        let l = self.llt.l();
        let mut v = x.to_owned();
        for &j in &self.slipping {
            for c in 0..v.ncols() {
                v[(j, c)] = 0.0;
            }
        }
        tri::solve_lower_triangular_in_place(l, v.as_mut(), Par::rayon(0));
        let s = self.slipping.len();
        let mut y0 = Mat::<Real>::zeros(s, x.ncols());
        for (p, column) in columns.iter().enumerate() {
            for c in 0..x.ncols() {
                y0[(p, c)] = column.iter().enumerate().map(|(i, a)| a * v[(i, c)]).sum();
            }
        }
        // K x_S − (I − K R⁻¹) y⁰_S.
        let mut r = Mat::<Real>::zeros(s, x.ncols());
        for (p, row) in self.kappa.iter().enumerate() {
            for c in 0..x.ncols() {
                let mut value = -y0[(p, c)];
                for &(q, kv) in row {
                    let j = self.slipping[q];
                    value += kv * (x[(j, c)] + y0[(q, c)] / self.reference[j]);
                }
                r[(p, c)] = value;
            }
        }
        schur.solve_in_place(r.as_mut());
        for (p, column) in columns.iter().enumerate() {
            for c in 0..x.ncols() {
                let w = r[(p, c)];
                for (i, a) in column.iter().enumerate() {
                    v[(i, c)] += a * w;
                }
            }
        }
        tri::solve_upper_triangular_in_place(l.transpose(), v.as_mut(), Par::rayon(0));
        x.copy_from(&v);
        true
    }

    /// The solve with two solves by `F` (`y⁰`, then `y = F⁻¹ w`).
    fn solve_twice(&self, mut x: MatMut<'_, Real>) {
        let mut y0 = x.to_owned();
        for &j in &self.slipping {
            for c in 0..y0.ncols() {
                y0[(j, c)] = 0.0;
            }
        }
        self.llt.solve_in_place(y0.as_mut());
        let Some(schur) = &self.schur else {
            x.copy_from(&y0);
            return;
        };
        // K x_S − (I − K R⁻¹) y⁰_S.
        let mut r = Mat::<Real>::zeros(self.slipping.len(), x.ncols());
        for (p, row) in self.kappa.iter().enumerate() {
            for c in 0..x.ncols() {
                let mut v = -y0[(self.slipping[p], c)];
                for &(q, kv) in row {
                    let j = self.slipping[q];
                    v += kv * (x[(j, c)] + y0[(j, c)] / self.reference[j]);
                }
                r[(p, c)] = v;
            }
        }
        schur.solve_in_place(r.as_mut());
        for (p, &j) in self.slipping.iter().enumerate() {
            for c in 0..x.ncols() {
                x[(j, c)] = r[(p, c)];
            }
        }
        self.llt.solve_in_place(x);
    }
}

impl FrictionInverse {
    /// Border `m` new rows into the factor: `a12` (n × m) their coupling `A12` with the
    /// factor's rows, `a22` (m × m) `A22 + R⁻¹` among themselves (`R` their
    /// [`reference_stiffness`]), `reference` and `reference_slips` theirs. `F` becomes
    /// `[F A12; A21 A22 + R⁻¹]` with `L21 = A21 L11⁻ᵀ`, `L22 = chol(A22 + R⁻¹ − L21 L21ᵀ)`
    /// (`n² m` flops), and the kept columns of `L⁻¹` are extended
    /// (`[x; −L22⁻¹ L21 x]`). `Err` (nothing changed) if the new block is not positive
    /// definite.
    fn border(
        &mut self,
        a12: Mat<Real>,
        mut a22: Mat<Real>,
        reference: &[Real],
        reference_slips: &[bool],
    ) -> Result<(), String> {
        use faer::linalg::triangular_solve as tri;
        let n = self.reference.len();
        let m = a22.nrows();
        let mut l21t = a12;
        tri::solve_lower_triangular_in_place(self.llt.l(), l21t.as_mut(), Par::rayon(0));
        faer::linalg::matmul::matmul(
            a22.as_mut(),
            Accum::Add,
            l21t.transpose(),
            l21t.as_ref(),
            -1.0,
            Par::rayon(0),
        );
        let l22 = a22
            .llt(Side::Lower)
            .map_err(|e| format!("the bordered contact matrix is not positive definite: {e:?}"))?;
        let mut l = Mat::<Real>::zeros(n + m, n + m);
        l.as_mut().submatrix_mut(0, 0, n, n).copy_from(self.llt.l());
        l.as_mut()
            .submatrix_mut(n, 0, m, n)
            .copy_from(l21t.transpose());
        l.as_mut().submatrix_mut(n, n, m, m).copy_from(l22.L());
        // The kept columns of L⁻¹: the new rows' part of L⁻¹ e_j is −L22⁻¹ L21 (L11⁻¹ e_j).
        let kept: Vec<usize> = self.columns.keys().copied().collect();
        if !kept.is_empty() {
            let mut x = Mat::<Real>::zeros(n, kept.len());
            for (q, j) in kept.iter().enumerate() {
                for (i, &v) in self.columns[j].iter().enumerate() {
                    x[(i, q)] = v;
                }
            }
            let mut y = Mat::<Real>::zeros(m, kept.len());
            faer::linalg::matmul::matmul(
                y.as_mut(),
                Accum::Replace,
                l21t.transpose(),
                x.as_ref(),
                -1.0,
                Par::rayon(0),
            );
            tri::solve_lower_triangular_in_place(l22.L(), y.as_mut(), Par::rayon(0));
            for (q, j) in kept.iter().enumerate() {
                if let Some(column) = self.columns.get_mut(j) {
                    column.extend((0..m).map(|i| y[(i, q)]));
                }
            }
        }
        self.llt = Factor::Bordered(l);
        // `Z` was of the factor before: every entry now has the new rows' part too.
        self.z = None;
        self.reference.extend_from_slice(reference);
        self.reference_slips.extend_from_slice(reference_slips);
        self.gone.extend(std::iter::repeat_n(false, m));
        Ok(())
    }
}

/// A row's nonzero entries, as (body, candidate slot, coefficient).
type Entries = Vec<(usize, usize, Real)>;

/// Contact rows as Cartesian node rows: a contact with friction in 3D (three rows, the
/// normal and two tangents) has the same node entries in each row, the weight `w` of an
/// entry at a node's DOF `k` times the row's axis component `axis[k]`. Its `G C Gᵀ` blocks
/// are then `axesᵀ (G̃ C G̃ᵀ) axes`, with `G̃` three Cartesian rows (x, y, z) of the weights
/// alone, each with a third of the entries: the sums over entries pairs cost 3× fewer
/// multiply-adds and reads of `C`. Any other row (frictionless, 2D, a contact whose rows do
/// not have this form) is its own Cartesian row, its projection the identity.
struct Cartesian {
    /// The Cartesian rows (a contact's x, y, z; or a row of its own).
    rows: Vec<Entries>,
    /// Each group of rows in order: its first contact row and first Cartesian row, and the
    /// contact's axes (as rows; `None`: one row of its own).
    groups: Vec<(usize, usize, Option<Matrix3<Real>>)>,
}

/// How far an entry of a contact's row may be from its weight times the row's axis
/// component, relative to the weight, for the contact to be taken as Cartesian rows: the
/// round-off of forming the entries and of recovering the weight (`Σ_r v_r axis_r`), with
/// orthonormal axes.
const CARTESIAN_TOLERANCE: Real = 1e-14;

impl Cartesian {
    fn new(rows: &[ContactRow]) -> Self {
        let mut out = Cartesian {
            rows: Vec::with_capacity(rows.len()),
            groups: Vec::with_capacity(rows.len()),
        };
        let mut i = 0;
        while i < rows.len() {
            if let Some((axes, xyz)) = Self::contact(&rows[i..]) {
                out.groups.push((i, out.rows.len(), Some(axes)));
                out.rows.extend(xyz);
                i += 3;
            } else {
                out.groups.push((i, out.rows.len(), None));
                out.rows.push(rows[i].entries.clone());
                i += 1;
            }
        }
        out
    }

    /// The Cartesian rows of the contact whose rows start `rows`, and its axes (as rows of a
    /// matrix), when its three rows have the form `w axis[k]` on the same entries.
    fn contact(rows: &[ContactRow]) -> Option<(Matrix3<Real>, [Entries; 3])> {
        let [r0, r1, r2] = rows.get(..3)? else {
            return None;
        };
        let f = r0.friction?;
        let same = |r: &ContactRow| {
            r.friction
                .is_some_and(|g| g.first == f.first && g.count == 3 && g.contact == f.contact)
                && r.entries.len() == r0.entries.len()
                && r.entries
                    .iter()
                    .zip(&r0.entries)
                    .all(|(a, b)| a.0 == b.0 && a.1 == b.1)
        };
        if f.count != 3 || !same(r1) || !same(r2) {
            return None;
        }
        let axes = [f.axis, r1.friction?.axis, r2.friction?.axis];
        let mut xyz: [Entries; 3] = Default::default();
        for (j, &(b, s, _)) in r0.entries.iter().enumerate() {
            let v = [r0.entries[j].2, r1.entries[j].2, r2.entries[j].2];
            // The entry's Cartesian direction: `Σ_r v_r axis_r = w e_k` for orthonormal axes.
            let u = axes[0] * v[0] + axes[1] * v[1] + axes[2] * v[2];
            let k = u.iamax();
            let w = u[k];
            if w == 0.0 {
                if v.iter().all(|&x| x == 0.0) {
                    continue;
                }
                return None;
            }
            if (0..3).any(|r| (v[r] - w * axes[r][k]).abs() > CARTESIAN_TOLERANCE * w.abs()) {
                return None;
            }
            xyz[k].push((b, s, w));
        }
        Some((
            Matrix3::from_rows(&[
                axes[0].transpose(),
                axes[1].transpose(),
                axes[2].transpose(),
            ]),
            xyz,
        ))
    }
}

/// Which part of `G C Gᵀ` [`coupling`] forms.
#[derive(Clone, Copy, PartialEq)]
enum Part {
    /// Every entry.
    Whole,
    /// The rows' own (left and right the same rows) lower triangle, the diagonal blocks of the
    /// contacts whole, zero above them: all that a Cholesky factor of the lower side reads.
    Lower,
}

/// `G_left C G_rightᵀ` for two lists of contact rows (m/N: the left rows' relative
/// motion per unit force on the right rows), or with [`Part::Lower`] the lower triangle of
/// `G C Gᵀ` for `left` (= `right`), through their Cartesian rows (see [`Cartesian`]): per
/// right group (on every core), its columns `W_b = C_b G̃_bᵀ` per body touched (a thread's
/// buffer, kept in cache for what follows), then per left group the Cartesian block (each
/// entry the sum over the left Cartesian row's entries of `W`) projected on the two groups'
/// axes. Each entry's sums go in a fixed order whatever the threads, so the matrix is the
/// same bitwise on any number of cores.
fn coupling(
    bodies: &[&CondensedBody],
    left: &[ContactRow],
    right: &[ContactRow],
    part: Part,
) -> Mat<Real> {
    let (l, r) = (Cartesian::new(left), Cartesian::new(right));
    let mut a = Mat::<Real>::zeros(left.len(), right.len());
    // The columns of `a` of each right group.
    let mut blocks = Vec::with_capacity(r.groups.len());
    let mut rest = a.as_mut();
    for &(_, _, axes) in &r.groups {
        let (block, tail) = rest.split_at_col_mut(if axes.is_some() { 3 } else { 1 });
        blocks.push(block);
        rest = tail;
    }
    let sizes: Vec<usize> = bodies.iter().map(|b| b.len()).collect();
    blocks
        .into_par_iter()
        .zip(r.groups.par_iter())
        .for_each_init(
            || vec![Vec::<Real>::new(); 3 * bodies.len()],
            |buffers, (mut block, &(rr, rq, raxes))| {
                let width = block.ncols();
                // W's columns of the group per body (`None`: the row does not touch the body).
                let mut touched_any = vec![false; 3 * bodies.len()];
                for q in 0..width {
                    for (b, &m) in sizes.iter().enumerate() {
                        let column = &mut buffers[q * bodies.len() + b];
                        let mut any = false;
                        for &(bb, s, v) in &r.rows[rq + q] {
                            if bb != b {
                                continue;
                            }
                            if !any {
                                column.clear();
                                column.resize(m, 0.0);
                                any = true;
                            }
                            let c = bodies[b].compliance_column(s);
                            for (x, &ci) in column.iter_mut().zip(c) {
                                *x += v * ci;
                            }
                        }
                        touched_any[q * bodies.len() + b] = any;
                    }
                }
                for &(lr, lq, laxes) in &l.groups {
                    if part == Part::Lower && lr < rr {
                        continue;
                    }
                    let height = if laxes.is_some() { 3 } else { 1 };
                    let mut m = Matrix3::<Real>::zeros();
                    for p in 0..height {
                        for q in 0..width {
                            let mut sum = 0.0;
                            for &(b, s, v) in &l.rows[lq + p] {
                                let i = q * bodies.len() + b;
                                if touched_any[i] {
                                    sum += v * buffers[i][s];
                                }
                            }
                            m[(p, q)] = sum;
                        }
                    }
                    // axes_l G̃ C G̃ᵀ axes_rᵀ (an identity for a row of its own).
                    let m = match laxes {
                        Some(al) => al * m,
                        None => m,
                    };
                    let m = match raxes {
                        Some(ar) => m * ar.transpose(),
                        None => m,
                    };
                    for p in 0..height {
                        for q in 0..width {
                            block[(lr + p, q)] = m[(p, q)];
                        }
                    }
                }
            },
        );
    #[cfg(test)]
    check_coupling(bodies, left, right, part, &a, &l);
    a
}

#[cfg(test)]
thread_local! {
    /// While `Some`: each [`coupling`] on this thread is checked against
    /// [`coupling_by_rows`], recording the largest difference of an entry relative to
    /// `sqrt(A_ii A_jj)` (its bound for a symmetric positive semidefinite `G C Gᵀ`), the
    /// contacts taken as Cartesian rows, those of them touching two bodies, and the calls
    /// forming the whole matrix (a kept Jacobian's border).
    static COUPLING_CHECK: Cell<Option<(Real, usize, usize, usize)>> = const { Cell::new(None) };
}

/// Start (`true`) or stop checking [`coupling`] on this thread; returns what was recorded
/// since the start (largest relative difference, Cartesian contacts, of them touching two
/// bodies, whole-matrix calls).
#[cfg(test)]
pub(crate) fn check_couplings(on: bool) -> Option<(Real, usize, usize, usize)> {
    COUPLING_CHECK.with(|c| c.replace(on.then_some((0.0, 0, 0, 0))))
}

/// `G_left C G_rightᵀ` row by row, entry by entry (the reference of [`coupling`]).
#[cfg(test)]
fn coupling_by_rows(
    bodies: &[&CondensedBody],
    left: &[ContactRow],
    right: &[ContactRow],
) -> Mat<Real> {
    let entry = |a: &ContactRow, b: &ContactRow| {
        let mut sum = 0.0;
        for &(b1, s1, v1) in &a.entries {
            for &(b2, s2, v2) in &b.entries {
                if b1 == b2 {
                    sum += v1 * v2 * bodies[b1].compliance_column(s2)[s1];
                }
            }
        }
        sum
    };
    Mat::from_fn(left.len(), right.len(), |i, j| entry(&left[i], &right[j]))
}

/// Record how far `a` (of [`coupling`]) is from [`coupling_by_rows`] when checking.
#[cfg(test)]
fn check_coupling(
    bodies: &[&CondensedBody],
    left: &[ContactRow],
    right: &[ContactRow],
    part: Part,
    a: &Mat<Real>,
    l: &Cartesian,
) {
    let Some((mut worst, mut cartesian, mut two, mut whole)) = COUPLING_CHECK.with(Cell::get)
    else {
        return;
    };
    let reference = coupling_by_rows(bodies, left, right);
    let own = |rows: &[ContactRow]| -> Vec<Real> {
        rows.iter()
            .map(|r| {
                coupling_by_rows(bodies, std::slice::from_ref(r), std::slice::from_ref(r))[(0, 0)]
            })
            .collect()
    };
    let (dl, dr) = (own(left), own(right));
    for j in 0..right.len() {
        for i in 0..left.len() {
            // `Part::Lower` forms the lower triangle (and the contacts' diagonal blocks).
            if part == Part::Lower && i < j {
                continue;
            }
            let scale = (dl[i] * dr[j]).sqrt();
            worst = worst.max((a[(i, j)] - reference[(i, j)]).abs() / scale);
        }
    }
    for &(row, _, axes) in &l.groups {
        if axes.is_some() {
            cartesian += 1;
            let b0 = left[row].entries.first().map(|e| e.0);
            if left[row].entries.iter().any(|e| Some(e.0) != b0) {
                two += 1;
            }
        }
    }
    whole += usize::from(part == Part::Whole);
    COUPLING_CHECK.with(|c| c.set(Some((worst, cartesian, two, whole))));
}

/// A Newton correction of the condensed contact problem.
pub(crate) struct Correction {
    /// Change of the contact forces at each body's candidate slots, N.
    pub fhat: Vec<Vec<Real>>,
    /// Change of each body's rigid-motion amplitudes, m.
    pub alpha: Vec<Vec<Real>>,
    /// Whether a rigid motion had nothing holding it (moved by the stabilisation).
    pub stabilised: bool,
}

/// The factored Jacobian of the condensed contact problem for a list of contact rows:
///
/// `δf̂ = Φ₁ − Gᵀμ`, `(κ⁻¹ + G C Gᵀ) μ = G C Φ₁ + B δα`, `Bᵀ μ = R_Cᵀ Φ₁ + Φ₂`, `B = G R_C`,
///
/// for residuals `Φ₁` (contact force found minus assumed at each body's candidates, N) and
/// `Φ₂` (out-of-balance of each body along its rigid motions, N): a dense problem of the size
/// of the active contacts, factored once and reused while Newton converges with it (a modified
/// Newton step when the contacts' normals and weights have moved a little; with friction, one
/// row per contact direction and the contacts' states brought up to date, see
/// [`ContactJacobian::restiffen`]). Rigid motions the
/// contacts do not hold (an eigenvalue of `Bᵀ A⁻¹ B` below 1000 `stabilisation`, N/m) are moved
/// by their out-of-balance over `stabilisation`, as the coupled solve does.
pub(crate) struct ContactJacobian {
    rows: Vec<ContactRow>,
    llt: Inverse,
    /// `[B | A⁻¹ B]`, k × 2r.
    b_psi: Mat<Real>,
    /// First rigid amplitude of each body in the global list.
    first: Vec<usize>,
    /// Eigenvalues and eigenvectors of `Bᵀ A⁻¹ B` (none without rigid motions).
    eigen: Option<nalgebra::SymmetricEigen<Real, nalgebra::Dyn>>,
    /// LU of `Bᵀ A⁻¹ B` itself when it is unsymmetric (friction).
    rigid_lu: Option<nalgebra::LU<Real, nalgebra::Dyn, nalgebra::Dyn>>,
    stabilisation: Real,
}

impl ContactJacobian {
    /// Form and factor the Jacobian for `rows`.
    /// With friction and `exact`, every slipping contact's tangent is taken exactly (a Schur
    /// complement on all their rows); without, only those that changed state since (see
    /// [`FrictionInverse`]).
    pub(crate) fn new(
        bodies: &[&CondensedBody],
        rows: Vec<ContactRow>,
        stabilisation: Real,
        exact: bool,
    ) -> Result<Self, String> {
        let k = rows.len();
        let clock = std::time::Instant::now();
        let general = rows.iter().any(|r| r.friction.is_some());
        if general
            && rows
                .iter()
                .any(|r| !(r.penalty > 0.0 && r.penalty.is_finite()))
        {
            return Err("a contact row has no positive stiffness".into());
        }
        // A = κ⁻¹ + G C Gᵀ; with friction `F = R⁻¹ + G C Gᵀ`, the rows' reference
        // stiffnesses.
        let reference = if general {
            reference_stiffness(&rows, exact)
        } else {
            rows.iter().map(|r| r.penalty).collect()
        };
        let mut a = coupling(bodies, &rows, &rows, Part::Lower);
        for (e, r) in reference.iter().enumerate() {
            a[(e, e)] += 1.0 / r;
        }
        let t_form = clock.elapsed().as_secs_f64();
        // Only the lower triangle is formed: the factorizations below read nothing else.
        let llt = if general {
            Inverse::Friction(Box::new(FrictionInverse::new(a, &rows, exact)?))
        } else {
            Inverse::Symmetric(
                a.llt(Side::Lower)
                    .map_err(|e| format!("the contact matrix is not positive definite: {e:?}"))?,
            )
        };
        let t_factor = clock.elapsed().as_secs_f64();
        let mut first = Vec::with_capacity(bodies.len());
        let mut r = 0;
        for b in bodies {
            first.push(r);
            r += b.modes.len();
        }
        let mut jacobian = ContactJacobian {
            rows,
            llt,
            b_psi: Mat::zeros(0, 0),
            first,
            eigen: None,
            rigid_lu: None,
            stabilisation,
        };
        jacobian.rigid(bodies, r);
        if crate::contact::condensed::solver::trace() {
            eprintln!(
                "friction-trace fresh rows {k} form {t_form:.3} factor {:.3} rigid {:.3}",
                t_factor - t_form,
                clock.elapsed().as_secs_f64() - t_factor
            );
        }
        Ok(jacobian)
    }

    /// `B`, `A⁻¹ B` and `Bᵀ A⁻¹ B` of the `r` rigid motions, with the factor as it is.
    fn rigid(&mut self, bodies: &[&CondensedBody], r: usize) {
        let k = self.rows.len();
        // B = G R_C, then A⁻¹ B beside it.
        let mut b_psi = Mat::<Real>::zeros(k, 2 * r);
        for (e, row) in self.rows.iter().enumerate() {
            for &(b, s, v) in &row.entries {
                for (j, mode) in bodies[b].modes_c.iter().enumerate() {
                    b_psi[(e, self.first[b] + j)] += v * mode[s];
                    b_psi[(e, r + self.first[b] + j)] += v * mode[s];
                }
            }
        }
        self.llt.solve_in_place(b_psi.subcols_mut(r, r));
        let mut m = nalgebra::DMatrix::<Real>::zeros(r, r);
        for i in 0..r {
            for j in 0..r {
                m[(i, j)] = (0..k).map(|e| b_psi[(e, i)] * b_psi[(e, r + j)]).sum();
            }
        }
        // With slipping contacts `Bᵀ A⁻¹ B` is unsymmetric: the held rigid motions are decided
        // on its symmetric part and, when all are held, solved with the whole of it.
        self.rigid_lu = matches!(self.llt, Inverse::Friction(_)).then(|| m.clone().lu());
        let m = (&m + m.transpose()) * 0.5;
        self.eigen = (r > 0).then(|| m.symmetric_eigen());
        self.b_psi = b_psi;
    }

    /// Whether the Jacobian is of contacts with friction and takes the slipping contacts'
    /// tangents only approximately (see [`FrictionInverse`]).
    pub(crate) fn is_approximate(&self) -> bool {
        self.llt.approximate().is_some()
    }

    /// Whether the Jacobian is of contacts with friction.
    pub(crate) fn has_friction(&self) -> bool {
        matches!(self.llt, Inverse::Friction(_))
    }

    /// Whether `rows` are the Jacobian's contacts with friction, each sticking or slipping as
    /// when the Jacobian last took their states (their stiffnesses may differ).
    pub(crate) fn same_states(&self, rows: &[ContactRow]) -> bool {
        self.has_friction()
            && rows.len() == self.rows.len()
            && self
                .rows
                .iter()
                .zip(rows)
                .all(|(old, new)| match (&old.friction, &new.friction) {
                    (Some(a), Some(b)) => {
                        a.first == b.first
                            && a.count == b.count
                            && a.contact == b.contact
                            && a.slipping.is_some() == b.slipping.is_some()
                    }
                    (None, None) => true,
                    _ => false,
                })
    }

    /// Take which contacts slip, and their stiffnesses, from `rows` (the same contacts at a
    /// later iterate) into a Jacobian with friction, keeping its `G C Gᵀ`, its factor and its
    /// rows' directions (a modified Newton step in `G`, exact in the friction law's state):
    /// `false`, and nothing changed, if it has no friction or `rows` are other contacts.
    pub(crate) fn restiffen(&mut self, bodies: &[&CondensedBody], rows: &[ContactRow]) -> bool {
        if !self.has_friction() || rows.len() != self.rows.len() {
            return false;
        }
        let same =
            self.rows
                .iter()
                .zip(rows)
                .all(|(old, new)| match (&old.friction, &new.friction) {
                    (Some(a), Some(b)) => {
                        a.first == b.first && a.count == b.count && a.contact == b.contact
                    }
                    (None, None) => true,
                    _ => false,
                });
        if !same {
            return false;
        }
        // Beyond a share of the rows changing state since the factorization, the Schur
        // complement (`k² s` for its columns) costs more than a new factor (`k³/3`).
        if let Inverse::Friction(f) = &self.llt {
            let changed = rows
                .iter()
                .zip(&f.reference_slips)
                .filter(|&(r, &was)| slips(r) != was)
                .count();
            if f.exact && rows.len() >= approximate_from() && !few_slip(rows) {
                return false;
            }
            if !f.exact && changed * MOST_CHANGED > rows.len() {
                return false;
            }
        }
        for (old, new) in self.rows.iter_mut().zip(rows) {
            if let (Some(a), Some(b)) = (&mut old.friction, &new.friction) {
                a.slipping = b.slipping;
            }
        }
        let changed = match &mut self.llt {
            Inverse::Friction(f) => f.set_stiffness(&self.rows),
            Inverse::Symmetric(_) => true,
        };
        // The rigid motions' terms depend on the rows' directions and the inverse only.
        if changed {
            let r = self.b_psi.ncols() / 2;
            self.rigid(bodies, r);
        }
        true
    }

    /// Take another contact set's `rows` into a kept Jacobian with friction, as
    /// [`ContactJacobian::restiffen`] does for the same set: the rows of contacts still in
    /// the set (found by their contact's key) keep their factored `G C Gᵀ` and directions and
    /// take their new states; contacts that left the set become rows of zero stiffness in the
    /// exact Schur complement (their force zero, so the kept factor solves exactly as a fresh
    /// factor of the remaining rows would); contacts new to the set are bordered into the
    /// Cholesky factor (see [`FrictionInverse::border`]). With `keep_if_same`, nothing is
    /// formed again when the set and every contact's state are those the Jacobian has.
    /// `false`, and nothing changed, below [`approximate_from`] rows (the exact path there
    /// forms a Jacobian per set), without friction or keys, when the factor should change from
    /// exact to approximate, or when more than one row in [`MOST_CHANGED`] would be new, or in
    /// the Schur complement (gone, or, with an approximate factor, in another state than at
    /// factorization): a fresh factor costs less then.
    pub(crate) fn adopt(
        &mut self,
        bodies: &[&CondensedBody],
        rows: &[ContactRow],
        keep_if_same: bool,
    ) -> bool {
        let clock = std::time::Instant::now();
        let Inverse::Friction(f) = &self.llt else {
            return false;
        };
        let n = self.rows.len();
        if rows.len() < approximate_from() || n < approximate_from() {
            return false;
        }
        if f.exact && !few_slip(rows) {
            return false;
        }
        // Each new row by its contact's key and its place among the contact's rows.
        let mut at: HashMap<(FrictionKey, usize), usize> = HashMap::with_capacity(rows.len());
        for (i, r) in rows.iter().enumerate() {
            let Some((fr, key)) = r.friction.and_then(|fr| fr.contact.map(|k| (fr, k))) else {
                return false;
            };
            if at.insert((key, i - fr.first), i).is_some() {
                return false;
            }
        }
        // The Jacobian's rows matched to the new ones (`None`: the contact left the set).
        let mut matched: Vec<Option<usize>> = vec![None; n];
        let mut taken = vec![false; rows.len()];
        for (j, r) in self.rows.iter().enumerate() {
            let Some((fr, key)) = r.friction.and_then(|fr| fr.contact.map(|k| (fr, k))) else {
                return false;
            };
            if let Some(&i) = at.get(&(key, j - fr.first)) {
                if rows[i].friction.is_some_and(|g| g.count == fr.count) {
                    matched[j] = Some(i);
                    taken[i] = true;
                }
            }
        }
        let added: Vec<usize> = (0..rows.len()).filter(|&i| !taken[i]).collect();
        let gone = matched.iter().filter(|m| m.is_none()).count();
        let changed = if f.exact {
            0
        } else {
            matched
                .iter()
                .enumerate()
                .filter(|&(j, m)| m.is_some_and(|i| slips(&rows[i]) != f.reference_slips[j]))
                .count()
        };
        if (gone + changed) * MOST_CHANGED > n + added.len() || added.len() * MOST_CHANGED > n {
            return false;
        }
        let same = added.is_empty()
            && matched.iter().enumerate().all(|(j, m)| match m {
                Some(i) => !f.gone[j] && slips(&rows[*i]) == slips(&self.rows[j]),
                None => f.gone[j],
            });
        if keep_if_same && same {
            return true;
        }
        // The new contacts' rows, with their positions in the Jacobian's rows.
        let mut new_rows: Vec<ContactRow> = Vec::with_capacity(added.len());
        for &i in &added {
            let r = &rows[i];
            let mut friction = r.friction;
            if let Some(fr) = friction.as_mut() {
                // `added` holds a contact's rows together, in order.
                fr.first = n + new_rows.len() - (i - fr.first);
            }
            new_rows.push(ContactRow {
                penalty: r.penalty,
                entries: r.entries.clone(),
                friction,
            });
        }
        let new_rows_empty = new_rows.is_empty();
        if !new_rows_empty {
            let m = new_rows.len();
            let exact = f.exact;
            let reference = reference_stiffness(&new_rows, exact);
            let reference_slips: Vec<bool> = new_rows.iter().map(|r| slips(r) && !exact).collect();
            let mut all = std::mem::take(&mut self.rows);
            all.extend(new_rows);
            let a = coupling(bodies, &all, &all[n..], Part::Whole);
            let a12 = a.as_ref().submatrix(0, 0, n, m).to_owned();
            let mut a22 = Mat::<Real>::zeros(m, m);
            for i in 0..m {
                for j in 0..m {
                    a22[(i, j)] = 0.5 * (a[(n + i, j)] + a[(n + j, i)]);
                }
                a22[(i, i)] += 1.0 / reference[i];
            }
            let bordered = match &mut self.llt {
                Inverse::Friction(f) => f.border(a12, a22, &reference, &reference_slips),
                Inverse::Symmetric(_) => Err(String::new()),
            };
            if bordered.is_err() {
                all.truncate(n);
                self.rows = all;
                return false;
            }
            self.rows = all;
        }
        for (j, m) in matched.iter().enumerate() {
            if let (Some(i), Some(a)) = (m, self.rows[j].friction.as_mut()) {
                a.slipping = rows[*i].friction.and_then(|b| b.slipping);
            }
        }
        let changed = match &mut self.llt {
            Inverse::Friction(f) => {
                for (j, m) in matched.iter().enumerate() {
                    f.gone[j] = m.is_none();
                }
                f.set_stiffness(&self.rows)
            }
            Inverse::Symmetric(_) => true,
        };
        // New rows change `B` and the factor (and `set_stiffness` reports it); else the
        // rigid motions' terms depend on the inverse only.
        if changed || !new_rows_empty {
            let r = self.b_psi.ncols() / 2;
            self.rigid(bodies, r);
        }
        #[cfg(test)]
        if !added.is_empty() || gone > 0 {
            CARRIED.with(|c| c.set(c.get() + 1));
        }
        if crate::contact::condensed::solver::trace() {
            eprintln!(
                "friction-trace adopt rows {} added {} gone {gone} changed {changed} in {:.3}",
                self.rows.len(),
                added.len(),
                clock.elapsed().as_secs_f64()
            );
        }
        true
    }

    /// The contact rows the Jacobian was formed with.
    pub(crate) fn rows(&self) -> &[ContactRow] {
        &self.rows
    }

    /// The Newton correction for residuals `phi1` and `phi2` (see the type).
    pub(crate) fn correction(
        &self,
        bodies: &[&CondensedBody],
        phi1: &[Vec<Real>],
        phi2: &[Vec<Real>],
    ) -> Correction {
        let k = self.rows.len();
        let r = self.eigen.as_ref().map_or(0, |e| e.eigenvalues.len());
        // The bodies' compliance products side by side (each reads a dense compliance).
        let cphi: Vec<Vec<Real>> = bodies
            .par_iter()
            .zip(phi1)
            .map(|(b, p)| b.comply(p))
            .collect();
        // μ₀ = A⁻¹ G C Φ₁.
        let mut mu = Mat::<Real>::zeros(k, 1);
        for (e, row) in self.rows.iter().enumerate() {
            mu[(e, 0)] = row.entries.iter().map(|&(b, s, v)| v * cphi[b][s]).sum();
        }
        self.llt.solve_in_place(mu.as_mut());
        let mut dalpha = vec![0.0; r];
        let mut stabilised = false;
        if let Some(eigen) = &self.eigen {
            let mut g = nalgebra::DVector::<Real>::zeros(r);
            for (b, body) in bodies.iter().enumerate() {
                for (j, mode) in body.modes_c.iter().enumerate() {
                    g[self.first[b] + j] =
                        phi2[b][j] + mode.iter().zip(&phi1[b]).map(|(a, p)| a * p).sum::<Real>();
                }
            }
            for i in 0..r {
                g[i] -= (0..k)
                    .map(|e| self.b_psi[(e, i)] * mu[(e, 0)])
                    .sum::<Real>();
            }
            let mut x = nalgebra::DVector::<Real>::zeros(r);
            for (i, &lambda) in eigen.eigenvalues.iter().enumerate() {
                let v = eigen.eigenvectors.column(i);
                let p = v.dot(&g);
                // Held: a Newton step. Not held (no contact restrains it): a stabilised move.
                let held = lambda > 1e3 * self.stabilisation;
                if !held && p != 0.0 {
                    stabilised = true;
                }
                let stiffness = if held {
                    lambda
                } else {
                    lambda.max(0.0) + self.stabilisation
                };
                x += v * (p / stiffness);
            }
            if !stabilised {
                if let Some(x) = self.rigid_lu.as_ref().and_then(|lu| lu.solve(&g)) {
                    dalpha.copy_from_slice(x.as_slice());
                } else {
                    dalpha.copy_from_slice(x.as_slice());
                }
            } else {
                dalpha.copy_from_slice(x.as_slice());
            }
        }
        // μ = μ₀ + Ψ δα; δf̂ = Φ₁ − Gᵀ μ.
        let mut fhat: Vec<Vec<Real>> = phi1.to_vec();
        for (e, row) in self.rows.iter().enumerate() {
            let m = mu[(e, 0)]
                + (0..r)
                    .map(|j| self.b_psi[(e, r + j)] * dalpha[j])
                    .sum::<Real>();
            for &(b, s, v) in &row.entries {
                fhat[b][s] -= v * m;
            }
        }
        let alpha = bodies
            .iter()
            .enumerate()
            .map(|(b, body)| dalpha[self.first[b]..self.first[b] + body.modes.len()].to_vec())
            .collect();
        Correction {
            fhat,
            alpha,
            stabilised,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{DMatrix, DVector};

    /// Two contacts' `G C Gᵀ` (symmetric positive definite), their stick stiffnesses
    /// (k_n, k_t, k_t) per contact, a slipping block (k_n along the normal x, unsymmetric,
    /// singular along y) and a right-hand side.
    fn two_contacts() -> (DMatrix<Real>, [Real; 6], Matrix3<Real>, DVector<Real>) {
        let b = DMatrix::<Real>::from_fn(6, 6, |i, j| {
            ((i * 7 + j * 3) % 5) as Real * 0.1 + if i == j { 0.5 } else { 0.0 }
        });
        (
            &b * b.transpose(),
            [4.0, 2.0, 2.0, 5.0, 3.0, 3.0],
            Matrix3::new(5.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.5, 0.0, 0.8),
            DVector::from_vec(vec![1.0, -2.0, 0.5, 3.0, -1.0, 2.0]),
        )
    }

    /// Rows of two contacts of three rows each (see [`rows_of`]).
    fn rows(r: &[Real; 6], slipping: [Option<Matrix3<Real>>; 2]) -> Vec<ContactRow> {
        rows_of(r, &slipping, 0)
    }

    /// `(I + κ A)⁻¹ κ x` for two contacts (see [`direct_of`]).
    fn direct(
        a: &DMatrix<Real>,
        r: &[Real; 6],
        slipping: [Option<Matrix3<Real>>; 2],
        x: &DVector<Real>,
    ) -> DVector<Real> {
        direct_of(a, r, &slipping, x)
    }

    /// A symmetric positive definite `G C Gᵀ` of `k` rows.
    fn coupling_of(k: usize) -> DMatrix<Real> {
        let b = DMatrix::<Real>::from_fn(k, k, |i, j| {
            ((i * 7 + j * 3) % 5) as Real * 0.1 + if i == j { 0.5 } else { 0.0 }
        });
        &b * b.transpose() + DMatrix::<Real>::identity(k, k) * 0.1
    }

    /// Rows of contacts of three rows each along x, y, z, with stick stiffnesses `r` and each
    /// contact's slipping block (`None`: sticking), numbered from the contact `from`.
    fn rows_of(r: &[Real], slipping: &[Option<Matrix3<Real>>], from: usize) -> Vec<ContactRow> {
        (0..r.len())
            .map(|i| ContactRow {
                penalty: r[i],
                entries: Vec::new(),
                friction: Some(FrictionRow {
                    first: 3 * (i / 3),
                    count: 3,
                    axis: Vector3::ith(i % 3, 1.0),
                    slipping: slipping[i / 3],
                    contact: Some(FrictionKey::Obstacle {
                        body: 0,
                        node: from + i / 3,
                        obstacle: 0,
                    }),
                }),
            })
            .collect()
    }

    /// `(I + κ A)⁻¹ κ x` by a dense LU of the whole matrix, κ block-diagonal (a contact's
    /// block its slipping block, or its stick stiffnesses).
    fn direct_of(
        a: &DMatrix<Real>,
        r: &[Real],
        slipping: &[Option<Matrix3<Real>>],
        x: &DVector<Real>,
    ) -> DVector<Real> {
        let k = r.len();
        let mut kappa = DMatrix::<Real>::zeros(k, k);
        for c in 0..k / 3 {
            for i in 0..3 {
                for j in 0..3 {
                    kappa[(3 * c + i, 3 * c + j)] = match slipping[c] {
                        Some(k3) => k3[(i, j)],
                        None if i == j => r[3 * c + i],
                        None => 0.0,
                    };
                }
            }
        }
        let m = DMatrix::<Real>::identity(k, k) + &kappa * a;
        m.lu().solve(&(&kappa * x)).expect("regular")
    }

    /// `F = A + R⁻¹` of the rows `from..to` as a faer matrix.
    fn f_of(a: &DMatrix<Real>, r: &[Real], from: usize, to: usize) -> Mat<Real> {
        Mat::<Real>::from_fn(to - from, to - from, |i, j| {
            a[(from + i, from + j)] + if i == j { 1.0 / r[from + i] } else { 0.0 }
        })
    }

    /// `y = inverse x` for one right-hand side.
    fn solve_with(inverse: &FrictionInverse, x: &DVector<Real>) -> DVector<Real> {
        let mut y = Mat::<Real>::from_fn(x.len(), 1, |i, _| x[i]);
        inverse.solve_in_place(y.as_mut());
        DVector::from_fn(x.len(), |i, _| y[(i, 0)])
    }

    #[test]
    fn a_bordered_factor_equals_a_fresh_factor_of_all_its_rows() {
        // Four contacts (12 rows); the factor made for the first two, the last two bordered in.
        let a = coupling_of(12);
        let r = [4.0, 2.0, 2.0, 5.0, 3.0, 3.0, 6.0, 2.5, 2.5, 3.0, 1.0, 1.0];
        let (_, _, slip, _) = two_contacts();
        let x = DVector::from_fn(12, |i, _| ((i * 5 + 1) % 7) as Real - 3.0);
        let first: [Option<Matrix3<Real>>; 2] = [Some(slip), None];
        let mut inverse =
            FrictionInverse::new(f_of(&a, &r, 0, 6), &rows_of(&r[..6], &first, 0), true)
                .expect("positive definite");
        // The first contact slips: its columns of L⁻¹ are kept, and extended by the border.
        assert_eq!(inverse.columns.len(), 3);
        let full = f_of(&a, &r, 0, 12);
        let a12 = full.as_ref().submatrix(0, 6, 6, 6).to_owned();
        let a22 = full.as_ref().submatrix(6, 6, 6, 6).to_owned();
        inverse
            .border(a12, a22, &r[6..], &[false; 6])
            .expect("positive definite");
        let fresh = full.llt(Side::Lower).expect("positive definite");
        let (l, l_fresh) = (inverse.llt.l(), fresh.L());
        for i in 0..12 {
            for j in 0..=i {
                assert!(
                    (l[(i, j)] - l_fresh[(i, j)]).abs() <= 1e-12 * l_fresh[(i, i)].abs(),
                    "L[{i}, {j}] {} against {}",
                    l[(i, j)],
                    l_fresh[(i, j)]
                );
            }
        }
        // Solves with the bordered factor equal the whole problem's (the kept columns and new
        // ones in the Schur complement).
        for states in [
            [Some(slip), None, None, None],
            [Some(slip), None, None, Some(slip)],
            [None, Some(slip), Some(slip), None],
        ] {
            inverse.set_stiffness(&rows_of(&r, &states, 0));
            let y = solve_with(&inverse, &x);
            let expected = direct_of(&a, &r, &states, &x);
            assert!(
                (&y - &expected).amax() <= 1e-12 * expected.amax(),
                "{states:?}: {y} against {expected}"
            );
        }
    }

    #[test]
    fn rows_gone_from_the_set_solve_as_a_fresh_factor_of_the_rows_left() {
        // Four contacts factored; the second leaves the set (and the fourth slips): its rows
        // have no force, the others' answer is that of a fresh factor of the three left.
        let a = coupling_of(12);
        let r = [4.0, 2.0, 2.0, 5.0, 3.0, 3.0, 6.0, 2.5, 2.5, 3.0, 1.0, 1.0];
        let (_, _, slip, _) = two_contacts();
        let x = DVector::from_fn(12, |i, _| ((i * 5 + 1) % 7) as Real - 3.0);
        let sticking = [None; 4];
        let mut inverse =
            FrictionInverse::new(f_of(&a, &r, 0, 12), &rows_of(&r, &sticking, 0), true)
                .expect("positive definite");
        let states = [None, None, None, Some(slip)];
        for i in 3..6 {
            inverse.gone[i] = true;
        }
        inverse.set_stiffness(&rows_of(&r, &states, 0));
        let y = solve_with(&inverse, &x);
        // The fresh factor of the rows left: contacts 0, 2 and 3.
        let left: Vec<usize> = (0..3).chain(6..12).collect();
        let a_left = DMatrix::<Real>::from_fn(9, 9, |i, j| a[(left[i], left[j])]);
        let r_left: Vec<Real> = left.iter().map(|&i| r[i]).collect();
        let x_left = DVector::from_fn(9, |i, _| x[left[i]]);
        let expected = direct_of(&a_left, &r_left, &[None, None, Some(slip)], &x_left);
        for i in 3..6 {
            assert!(
                y[i].abs() <= 1e-12 * expected.amax(),
                "row {i} of a contact gone: {}",
                y[i]
            );
        }
        for (q, &i) in left.iter().enumerate() {
            assert!(
                (y[i] - expected[q]).abs() <= 1e-12 * expected.amax(),
                "row {i}: {} against {}",
                y[i],
                expected[q]
            );
        }
        // A fifth contact bordered in: removing and adding rows, then solving, equals a fresh
        // factor of the new set (a gone contact's rows, as a block of zero stiffness, have
        // no force).
        let a15 = coupling_of(15);
        let r15 = [
            4.0, 2.0, 2.0, 5.0, 3.0, 3.0, 6.0, 2.5, 2.5, 3.0, 1.0, 1.0, 2.0, 1.5, 1.5,
        ];
        let mut inverse =
            FrictionInverse::new(f_of(&a15, &r15, 0, 12), &rows_of(&r, &sticking, 0), true)
                .expect("positive definite");
        for i in 3..6 {
            inverse.gone[i] = true;
        }
        let full = f_of(&a15, &r15, 0, 15);
        let a12 = full.as_ref().submatrix(0, 12, 12, 3).to_owned();
        let a22 = full.as_ref().submatrix(12, 12, 3, 3).to_owned();
        inverse
            .border(a12, a22, &r15[12..], &[false; 3])
            .expect("positive definite");
        let states15 = [None, None, None, Some(slip), Some(slip)];
        inverse.set_stiffness(&rows_of(&r15, &states15, 0));
        let x15 = DVector::from_fn(15, |i, _| ((i * 5 + 1) % 7) as Real - 3.0);
        let y = solve_with(&inverse, &x15);
        let gone = [None, Some(Matrix3::zeros()), None, Some(slip), Some(slip)];
        let expected = direct_of(&a15, &r15, &gone, &x15);
        for i in 0..15 {
            assert!(
                (y[i] - expected[i]).abs() <= 1e-12 * expected.amax(),
                "row {i}: {} against {}",
                y[i],
                expected[i]
            );
        }
    }

    #[test]
    fn an_approximate_factor_keeps_slipping_contacts_reference_and_solves_changed_ones_exactly() {
        // The matrices of the test below; the factor made with the second contact slipping,
        // approximately: its reference is its block's diagonal (5, ~0, 0.8), the coupling 1.5
        // of its normal into its third row left out.
        let (a, r, slip, x) = two_contacts();
        let at_factor = rows(&r, [None, Some(slip)]);
        let reference = reference_stiffness(&at_factor, false);
        let expected_reference = [4.0, 2.0, 2.0, 5.0, SLIP_REFERENCE * 3.0, 0.8];
        assert_eq!(reference, expected_reference);
        let mut f = Mat::<Real>::zeros(6, 6);
        for i in 0..6 {
            for j in 0..6 {
                f[(i, j)] = a[(i, j)] + if i == j { 1.0 / reference[i] } else { 0.0 };
            }
        }
        let mut inverse = FrictionInverse::new(f, &at_factor, false).expect("positive definite");
        let solve = |inverse: &FrictionInverse| {
            let mut y = Mat::<Real>::zeros(6, 1);
            for i in 0..6 {
                y[(i, 0)] = x[i];
            }
            inverse.solve_in_place(y.as_mut());
            DVector::from_fn(6, |i, _| y[(i, 0)])
        };
        // States as at the factorization: the reference, a diagonal stiffness per row.
        inverse.set_stiffness(&at_factor);
        let approximate = direct(&a, &expected_reference, [None, None], &x);
        let y = solve(&inverse);
        assert!(
            (&y - &approximate).amax() <= 1e-9 * approximate.amax(),
            "{y} against {approximate}"
        );
        // Both contacts changed state (the first slips, the second sticks): exact.
        inverse.set_stiffness(&rows(&r, [Some(slip), None]));
        let exact = direct(&a, &r, [Some(slip), None], &x);
        let y = solve(&inverse);
        assert!(
            (&y - &exact).amax() <= 1e-8 * exact.amax(),
            "{y} against {exact}"
        );
    }

    #[test]
    fn the_split_solve_equals_the_solve_by_two_factor_solves() {
        // The factor made with the second contact slipping, then the first slips and the
        // second sticks (both in the Schur complement): one forward and one backward solve
        // by `L` with `X`'s columns give what two solves by `F` give.
        let (a, r, slip, x) = two_contacts();
        let at_factor = rows(&r, [None, Some(slip)]);
        let reference = reference_stiffness(&at_factor, false);
        let f = Mat::<Real>::from_fn(6, 6, |i, j| {
            a[(i, j)] + if i == j { 1.0 / reference[i] } else { 0.0 }
        });
        let mut inverse = FrictionInverse::new(f, &at_factor, false).expect("positive definite");
        inverse.set_stiffness(&rows(&r, [Some(slip), None]));
        let rhs = Mat::<Real>::from_fn(6, 2, |i, c| x[i] * (1.0 + c as Real) - c as Real);
        let mut twice = rhs.clone();
        inverse.solve_twice(twice.as_mut());
        let mut split = rhs.clone();
        assert!(inverse.solve_split(split.as_mut()));
        let largest = twice.norm_max();
        for i in 0..6 {
            for c in 0..2 {
                assert!(
                    (split[(i, c)] - twice[(i, c)]).abs() <= 1e-12 * largest,
                    "row {i} column {c}: {} against {}",
                    split[(i, c)],
                    twice[(i, c)]
                );
            }
        }
        // And the exact answer, the dense solve of the unsymmetric Jacobian.
        let exact = direct(&a, &r, [Some(slip), None], &x);
        for i in 0..6 {
            assert!((split[(i, 0)] - exact[i]).abs() <= 1e-8 * exact.amax());
        }
    }

    #[test]
    fn the_schur_complement_on_slipping_rows_solves_the_whole_unsymmetric_jacobian() {
        // A symmetric positive definite G C Gᵀ, stick stiffnesses (k_n, k_t, k_t) per contact
        // and a slipping block: k_n along the normal (x), unsymmetric, singular along y.
        let (a, r, slip, x) = two_contacts();
        let mut f = Mat::<Real>::zeros(6, 6);
        for i in 0..6 {
            for j in 0..6 {
                f[(i, j)] = a[(i, j)] + if i == j { 1.0 / r[i] } else { 0.0 };
            }
        }
        // Sticking, the second contact slipping, then the first slipping instead (the columns
        // of L⁻¹ kept from before for the second).
        let states = [
            [None, None],
            [None, Some(slip)],
            [Some(slip), None],
            [Some(slip), Some(slip)],
        ];
        let mut inverse =
            FrictionInverse::new(f, &rows(&r, states[0]), true).expect("positive definite");
        for state in states {
            inverse.set_stiffness(&rows(&r, state));
            let expected = direct(&a, &r, state, &x);
            let mut y = Mat::<Real>::zeros(6, 1);
            for i in 0..6 {
                y[(i, 0)] = x[i];
            }
            inverse.solve_in_place(y.as_mut());
            for i in 0..6 {
                assert!(
                    (y[(i, 0)] - expected[i]).abs() <= 1e-12 * expected.amax(),
                    "{state:?} row {i}: {} against {}",
                    y[(i, 0)],
                    expected[i]
                );
            }
        }
    }
}
