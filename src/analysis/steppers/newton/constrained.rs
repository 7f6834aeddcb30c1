//! The contact constraints of a Newton step: their rows on the free DOFs, and the
//! constrained solves on the factored K* (theory 8.6, 8.6a, 8.6b).

use super::secant::Secant;
use super::{Constraints, StepFailure};
use crate::assembly::System;
use crate::contact::Tangential;
use crate::contact::linearization::{Linearization, row_linearization};
use crate::profile::{self, Phase};
use crate::solver::{Forward, Solver};
use nalgebra::DVector;

/// Active constraint rows restricted to the free DOFs, and their gaps (normal rows first,
/// then the fixed tangential ones); the sliding rows carry known forces.
pub(super) struct Rows {
    pub(super) rows: Vec<Vec<(usize, f64)>>,
    pub(super) gaps: Vec<f64>,
    /// The number of normal rows (the first ones).
    pub(super) normal: usize,
    pub(super) sliding: Vec<(Vec<(usize, f64)>, usize, f64)>,
    /// Per fixed tangential condition (in their order), its row among `rows`, or None when
    /// the row acts on prescribed DOFs only: the support holds that slip already (an axis
    /// node held in x against a wall whose tangent is x) and the row is left out.
    pub(super) fixed: Vec<Option<usize>>,
    /// Per normal row, its exact derivatives where the row is not dg/dx.
    pub(super) exact: Vec<Option<Exact>>,
    /// The largest |gap| of the normal rows against its pair's tolerance (TOL of Hughes II-7).
    pub(super) worst_gap: f64,
}

/// The exact derivatives of a normal row on a deformable master, on the free DOFs (see
/// `contact::linearization`).
pub(super) struct Exact {
    pub(super) gradient: Vec<(usize, f64)>,
    /// (equation p, equation q, d C_p / d x_q).
    pub(super) row_jacobian: Vec<(usize, usize, f64)>,
    /// The equations the gradient or the row Jacobian names, each once.
    pub(super) equations: Vec<usize>,
}

impl Exact {
    /// The derivatives of a normal row whose force row is C + slide T (`slide` the signed
    /// Coulomb coefficient of a sliding entry, 0 otherwise): dg/dx, and dC/dx + slide dT/dx.
    pub(super) fn combined(l: &Linearization, slide: f64, system: &System) -> Exact {
        let jacobian = |p: usize, q: usize| {
            let mut v = l.row_jacobian[(p, q)];
            if slide != 0.0 {
                v += slide * l.tangent_jacobian[(p, q)];
            }
            v
        };
        Exact::of(l, &|i| l.gradient[i], &jacobian, system)
    }

    /// The derivatives of a sticking entry's tangential row T (on the free DOFs, `row`): its
    /// constraint's gradient is T, its force's derivative dT/dx.
    pub(super) fn tangential(l: &Linearization, row: &[(usize, f64)], system: &System) -> Exact {
        let mut exact = Exact::of(l, &|_| 0.0, &|p, q| l.tangent_jacobian[(p, q)], system);
        exact.gradient = row.to_vec();
        exact.equations.extend(row.iter().map(|(eq, _)| *eq));
        exact.equations.sort_unstable();
        exact.equations.dedup();
        exact
    }

    /// A row whose constraint gradient is `row` itself and whose force does not turn (a
    /// row against a rigid obstacle): no derivative terms.
    pub(super) fn plain(row: &[(usize, f64)]) -> Exact {
        let mut equations: Vec<usize> = row.iter().map(|(eq, _)| *eq).collect();
        equations.sort_unstable();
        equations.dedup();
        Exact {
            gradient: row.to_vec(),
            row_jacobian: Vec::new(),
            equations,
        }
    }

    /// The gradient `gradient(local DOF)` and row Jacobian `jacobian(p, q)` of `l` on the
    /// free DOFs.
    fn of(
        l: &Linearization,
        gradient: &dyn Fn(usize) -> f64,
        jacobian: &dyn Fn(usize, usize) -> f64,
        system: &System,
    ) -> Exact {
        let dofs: Vec<(Option<usize>, usize)> = l
            .dofs()
            .map(|(dof, local)| (system.equation[dof], local))
            .collect();
        let gradient_free = dofs
            .iter()
            .filter_map(|(eq, i)| eq.map(|eq| (eq, gradient(*i))))
            .filter(|(_, v)| *v != 0.0)
            .collect();
        let mut row_jacobian = Vec::new();
        let mut equations = Vec::new();
        for (p, i) in &dofs {
            let Some(p) = p else { continue };
            let mut named = gradient(*i) != 0.0;
            for (q, j) in &dofs {
                if let Some(q) = q {
                    let v = jacobian(*i, *j);
                    if v != 0.0 {
                        row_jacobian.push((*p, *q, v));
                    }
                    named |= v != 0.0 || jacobian(*j, *i) != 0.0;
                }
            }
            if named {
                equations.push(*p);
            }
        }
        Exact {
            gradient: gradient_free,
            row_jacobian,
            equations,
        }
    }
}

impl Rows {
    pub(super) fn empty() -> Rows {
        Rows {
            rows: Vec::new(),
            gaps: Vec::new(),
            normal: 0,
            sliding: Vec::new(),
            fixed: Vec::new(),
            exact: Vec::new(),
            worst_gap: 0.0,
        }
    }

    /// The sliding forces for normal multipliers `forces`, added into a free-DOF vector.
    pub(super) fn add_sliding_forces(&self, forces: &[f64], target: &mut [f64]) {
        for (row, entry, coefficient) in &self.sliding {
            let f = coefficient * forces.get(*entry).copied().unwrap_or(0.0);
            for (eq, c) in row {
                target[*eq] += f * c;
            }
        }
    }

    /// The tangential forces in the order of `Constraints::tangential`, from the multipliers
    /// of a solve (normal rows, then the fixed tangential rows kept); a fixed condition left
    /// to a support has none of its own (0).
    pub(super) fn tangential_forces(
        &self,
        tangential: &[Tangential],
        multipliers: &[f64],
    ) -> Vec<f64> {
        let mut fixed = self.fixed.iter();
        tangential
            .iter()
            .map(|t| match t {
                Tangential::Fixed { .. } => fixed
                    .next()
                    .expect("a row or none per fixed condition")
                    .map_or(0.0, |row| multipliers[row]),
                Tangential::Sliding { entry, coefficient } => coefficient * multipliers[*entry],
            })
            .collect()
    }
}

impl Constraints<'_> {
    /// The gap entry (pair, slave node) must have at the end of the step: its target, or 0.
    pub(super) fn target(&self, entry: (usize, usize)) -> f64 {
        self.targets
            .iter()
            .find(|(e, _)| *e == entry)
            .map_or(0.0, |(_, target)| *target)
    }

    /// Why an active entry has no row: its slave faces no master segment any more.
    pub(super) fn lost(&self, pair: usize, slave: usize) -> String {
        format!(
            "contact `{}`: {} faces no master segment any more (it lost its master while \
             closed)",
            self.pairs[pair].name,
            (self.describe)(slave)
        )
    }

    pub(super) fn rows(&self, d: &[f64], system: &System) -> Result<Rows, StepFailure> {
        let x = |n: usize| [self.start[n][0] + d[2 * n], self.start[n][1] + d[2 * n + 1]];
        let free = |row: Vec<(usize, f64)>| -> Vec<(usize, f64)> {
            row.into_iter()
                .filter_map(|(dof, c)| system.equation[dof].map(|eq| (eq, c)))
                .collect()
        };
        let mut rows = Rows::empty();
        let mut gaps = Vec::with_capacity(self.active.len());
        for &(pair, slave) in self.active {
            let gap = self.pairs[pair]
                .gap(slave, &x)
                .ok_or_else(|| StepFailure(self.lost(pair, slave)))?;
            rows.rows.push(free(gap.row(slave)));
            let violation = gap.gap - self.target((pair, slave));
            rows.gaps.push(violation);
            let tolerance = self.pairs[pair].options.tolerance;
            rows.worst_gap = rows.worst_gap.max(violation.abs() / tolerance);
            let exact = row_linearization(self.pairs, pair, slave, &gap, &x);
            rows.exact
                .push(exact.map(|l| Exact::combined(&l, 0.0, system)));
            gaps.push(gap);
        }
        rows.normal = rows.rows.len();
        for t in self.tangential {
            match *t {
                Tangential::Fixed { entry, target } => {
                    let row = gaps[entry].tangent_row(self.active[entry].1);
                    let slip: f64 = row.iter().map(|(dof, c)| c * d[*dof]).sum();
                    // a row whose free coefficients are round-off next to its largest one
                    // acts on prescribed DOFs only
                    let scale = row.iter().fold(0.0f64, |m, (_, c)| m.max(c.abs()));
                    let on_free = free(row);
                    if on_free.iter().all(|(_, c)| c.abs() <= 1e-12 * scale) {
                        rows.fixed.push(None);
                        continue;
                    }
                    rows.fixed.push(Some(rows.rows.len()));
                    rows.rows.push(on_free);
                    rows.gaps.push(slip - target);
                }
                Tangential::Sliding { entry, coefficient } => {
                    let row = free(gaps[entry].tangent_row(self.active[entry].1));
                    rows.sliding.push((row, entry, coefficient));
                }
            }
        }
        Ok(rows)
    }
}

/// The contact rows of an arc-length iterate and the two constrained solves of its
/// bordered step on the factored tangent (theory 5b): the residual with the rows' gaps, and
/// the load with the gaps held where they are, so that `du_R + d lambda u_t` keeps the rows'
/// linearized gaps closed for any `d lambda`, and its multipliers are `tau_R + d lambda tau_t`.
pub struct Bordered {
    rows: Rows,
}

impl Bordered {
    /// The rows of `constraints` at the increment `d` (all DOFs); none without contact.
    pub fn at(
        constraints: Option<&Constraints<'_>>,
        d: &[f64],
        system: &System,
    ) -> Result<Bordered, StepFailure> {
        let rows = match constraints {
            Some(c) => c.rows(d, system)?,
            None => Rows::empty(),
        };
        Ok(Bordered { rows })
    }

    /// R + C^T tau: the residual `residual` with the contact forces `forces`.
    pub fn balance(&self, residual: &[f64], forces: &[f64]) -> Vec<f64> {
        let mut balance = residual.to_vec();
        add_constraint_forces(&self.rows, forces, &mut balance);
        balance
    }

    /// Whether every row holds its gap within its pair's tolerance (Hughes II-7).
    pub fn hold(&self) -> bool {
        self.rows.worst_gap <= 1.0
    }

    /// The number of normal rows (the first multipliers).
    pub fn normal(&self) -> usize {
        self.rows.normal
    }

    /// The number of rows: the normal ones, then the fixed tangential ones (sticking).
    pub fn len(&self) -> usize {
        self.rows.rows.len()
    }

    /// Adds the sliding entries' friction forces for the multipliers `forces` (known forces
    /// of the iteration, as in Newton's) into `residual`.
    pub fn add_sliding_forces(&self, forces: &[f64], residual: &mut [f64]) {
        self.rows.add_sliding_forces(forces, residual);
    }

    /// The tangential forces of the conditions `tangential` (in their order) for the
    /// multipliers `forces`.
    pub fn tangential_forces(&self, tangential: &[Tangential], forces: &[f64]) -> Vec<f64> {
        self.rows.tangential_forces(tangential, forces)
    }

    /// (du_R, tau_R): K du_R = R + C^T tau_R and C du_R = -g; `forces` the multipliers so far.
    pub fn solve(
        &self,
        solver: &mut Solver,
        residual: Vec<f64>,
        forces: &[f64],
    ) -> Result<(Vec<f64>, Vec<f64>), StepFailure> {
        constrained_solve(solver, &self.rows, residual, forces, &Secant::new(false))
    }

    /// (u_t, tau_t): K u_t = q + C^T tau_t and C u_t = 0, for the load `load` (q).
    pub fn solve_load(
        &mut self,
        solver: &mut Solver,
        load: Vec<f64>,
        forces: &[f64],
    ) -> Result<(Vec<f64>, Vec<f64>), StepFailure> {
        let held = vec![0.0; self.rows.gaps.len()];
        let gaps = std::mem::replace(&mut self.rows.gaps, held);
        let solved = self.solve(solver, load, forces);
        self.rows.gaps = gaps;
        solved
    }
}

/// sum_i tau_i C_i^T added into a free-DOF vector.
pub(super) fn add_constraint_forces(rows: &Rows, forces: &[f64], target: &mut [f64]) {
    for (row, tau) in rows.rows.iter().zip(forces) {
        for (eq, c) in row {
            target[*eq] += tau * c;
        }
    }
}

/// The Schur complement solve on the factored K* = P^T L L^T P, in one back-substitution:
/// ```text
/// w = L^-1 P R,  (delta_0)_a = y_a . w,  S = C K*^-1 C^T,  S tau = -g - C delta_0,
/// delta = P^T L^-T (w + sum_rows tau_i sum_a c_ia y_a)      (y_a = L^-1 P e_a)
/// ```
/// (= delta_0 + K*^-1 C^T tau). Contact never refactors K*; the y_a come with the entries of
/// K*^-1 among the constrained equations (`Solver::know_inverse`, once per factorization).
///
/// With BFGS pairs (`secant`) K*^-1 is H = H_0 + W M W^T: S gains (C W) M (C W)^T, the
/// right-hand side (C W) M W^T R and delta W M W^T (R + C^T tau).
pub(super) fn constrained_solve(
    solver: &mut Solver,
    rows: &Rows,
    residual: Vec<f64>,
    forces: &[f64],
    secant: &Secant,
) -> Result<(Vec<f64>, Vec<f64>), StepFailure> {
    if rows.exact.iter().any(Option::is_some) {
        // before W^T R is formed: the exact solve forms its own
        return exact_solve(solver, rows, residual, forces, secant);
    }
    let m = rows.rows.len();
    let projected_residual = (!secant.is_empty()).then(|| secant.project(&residual));
    if m == 0 {
        let mut delta = residual;
        solver.solve(&mut delta);
        if let Some(p) = &projected_residual {
            secant.add_correction(p, &mut delta);
        }
        return Ok((delta, Vec::new()));
    }
    // entries with a zero coefficient, as the x entry of a row on a horizontal wall, are
    // left out: they would cost a path each for nothing
    let nonzero: Vec<Vec<(usize, f64)>> = rows
        .rows
        .iter()
        .map(|row| row.iter().filter(|(_, c)| *c != 0.0).copied().collect())
        .collect();
    let equations: Vec<usize> = nonzero.iter().flatten().map(|(eq, _)| *eq).collect();
    solver.know_inverse(&equations);
    let mut w = solver.forward(&residual);
    let schur_start = std::time::Instant::now();
    let local: Vec<Vec<(usize, f64)>> = nonzero
        .iter()
        .map(|row| {
            row.iter()
                .map(|(eq, c)| (solver.inverse_local(*eq), *c))
                .collect()
        })
        .collect();
    if local.iter().any(|row| row.is_empty()) {
        return Err(StepFailure(ON_PRESCRIBED_ONLY.into()));
    }
    // C W, a row per constraint (none without pairs)
    let projected_rows: Vec<DVector<f64>> = match &projected_residual {
        Some(_) => nonzero
            .iter()
            .map(|row| secant.project_sparse(row))
            .collect(),
        None => Vec::new(),
    };
    let weighted_rows: Vec<DVector<f64>> = projected_rows.iter().map(|r| secant.weigh(r)).collect();
    let weighted_residual = projected_residual.as_ref().map(|p| secant.weigh(p));
    let schur = nalgebra::DMatrix::from_fn(m, m, |i, j| {
        let mut s = 0.0;
        for (a, ca) in &local[i] {
            for (b, cb) in &local[j] {
                s += ca * cb * solver.inverse_entry(*a, *b);
            }
        }
        if projected_residual.is_some() {
            s += projected_rows[i].dot(&weighted_rows[j]);
        }
        s
    });
    let rhs = nalgebra::DVector::from_fn(m, |i, _| {
        let secant_part = match &weighted_residual {
            Some(mp) => projected_rows[i].dot(mp),
            None => 0.0,
        };
        -rows.gaps[i]
            - secant_part
            - nonzero[i]
                .iter()
                .map(|(eq, c)| c * solver.solution_entry(&w, *eq))
                .sum::<f64>()
    });
    let tau = schur
        .lu()
        .solve(&rhs)
        .ok_or_else(|| StepFailure(REDUNDANT.into()))?;
    for (row, t) in nonzero.iter().zip(tau.iter()) {
        for (eq, c) in row {
            solver.add_unit(&mut w, *eq, c * t);
        }
    }
    profile::add(Phase::Contact, schur_start);
    let unit_loads = (&projected_rows[..], tau.iter());
    let delta = backward(solver, w, secant, projected_residual, unit_loads);
    Ok((delta, tau.iter().copied().collect()))
}

/// The backward half of a constrained solve, plus the BFGS correction W M W^T of the whole
/// load: `projected_residual` = W^T R (None without pairs) and `projected[i]` = W^T of the
/// unit load that `loads[i]` scales (the two given as `(projected, loads)`).
fn backward<'a>(
    solver: &mut Solver,
    w: Forward,
    secant: &Secant,
    projected_residual: Option<DVector<f64>>,
    (projected, loads): (&[DVector<f64>], impl Iterator<Item = &'a f64>),
) -> Vec<f64> {
    let mut delta = solver.backward(w);
    if let Some(mut p) = projected_residual {
        for (row, f) in projected.iter().zip(loads) {
            p.axpy(*f, row, 1.0);
        }
        secant.add_correction(&p, &mut delta);
    }
    delta
}

const REDUNDANT: &str = "the contact constraints are redundant (singular Schur complement)";
const ON_PRESCRIBED_ONLY: &str = "a contact constraint acts on prescribed DOFs only (a supported slave node against its obstacle): it cannot be enforced";

/// The constrained solve with the exact linearization of the rows on deformable masters
/// (`contact::linearization`): Newton's step for R(d) + C(d)^T tau = 0, g(d) = 0 is
/// ```text
/// K* delta = R + C^T tau + A delta,   G delta = -g,   A = sum_i tau_i dC_i/dx,  G = dg/dx
/// ```
/// (tau in A from the last solve). A and the rows live on the few equations E the contact
/// touches, so with Z = (K*^-1)_EE and q = delta_E it closes on E:
/// ```text
/// [ I - Z A   -Z C_E^T ] [ q   ]   [ (K*^-1 R)_E ]
/// [ G_E        0       ] [ tau ] = [ -g          ],   delta = K*^-1 (R + C^T tau + A q)
/// ```
/// in the same single back-substitution as `constrained_solve`, and without refactoring.
/// BFGS pairs add W_E M W_E^T to Z, (W M W^T R)_E to the right-hand side and
/// W M W^T (R + C^T tau + A q) to delta.
fn exact_solve(
    solver: &mut Solver,
    rows: &Rows,
    residual: Vec<f64>,
    forces: &[f64],
    secant: &Secant,
) -> Result<(Vec<f64>, Vec<f64>), StepFailure> {
    use nalgebra::{DMatrix, DVector};
    let m = rows.rows.len();
    let mut equations: Vec<usize> = rows
        .rows
        .iter()
        .flatten()
        .filter(|(_, c)| *c != 0.0)
        .map(|(eq, _)| *eq)
        .collect();
    for e in rows.exact.iter().flatten() {
        equations.extend(&e.equations);
    }
    equations.sort_unstable();
    equations.dedup();
    let n = equations.len();
    let at = |eq: usize| equations.binary_search(&eq).expect("equation in E");
    solver.know_inverse(&equations);
    let mut w = solver.forward(&residual);
    let schur_start = std::time::Instant::now();
    let local: Vec<usize> = equations
        .iter()
        .map(|eq| solver.inverse_local(*eq))
        .collect();
    let projected_residual = (!secant.is_empty()).then(|| secant.project(&residual));
    // W at E, a row per equation (none without pairs)
    let w_at: Vec<DVector<f64>> = match &projected_residual {
        Some(_) => equations.iter().map(|eq| secant.row(*eq)).collect(),
        None => Vec::new(),
    };
    let weighted_at: Vec<DVector<f64>> = w_at.iter().map(|r| secant.weigh(r)).collect();
    let weighted_residual = projected_residual.as_ref().map(|p| secant.weigh(p));
    let z = DMatrix::from_fn(n, n, |i, j| {
        let h0 = solver.inverse_entry(local[i], local[j]);
        match &projected_residual {
            Some(_) => h0 + w_at[i].dot(&weighted_at[j]),
            None => h0,
        }
    });
    // A = sum_i tau_i dC_i/dx has a few entries a row (the slave's and its segment's
    // equations): kept as (p, q, A_pq), so that Z A costs n per entry, not n^2 per column
    let mut a: Vec<(usize, usize, f64)> = Vec::new();
    let mut c = DMatrix::<f64>::zeros(m, n);
    for (i, row) in rows.rows.iter().enumerate() {
        for (eq, v) in row.iter().filter(|(_, v)| *v != 0.0) {
            c[(i, at(*eq))] += v;
        }
        if c.row(i).iter().all(|v| *v == 0.0) {
            return Err(StepFailure(ON_PRESCRIBED_ONLY.into()));
        }
    }
    let mut g = c.clone();
    for (i, exact) in rows.exact.iter().enumerate() {
        let Some(e) = exact else { continue };
        let tau = forces.get(i).copied().unwrap_or(0.0);
        a.extend(
            e.row_jacobian
                .iter()
                .map(|(p, q, v)| (at(*p), at(*q), tau * v)),
        );
        g.row_mut(i).fill(0.0);
        for (eq, v) in &e.gradient {
            g[(i, at(*eq))] += v;
        }
    }
    let mut system = DMatrix::<f64>::zeros(n + m, n + m);
    // I - Z A, column q of Z A being the sum of A_pq Z[:, p]
    for i in 0..n {
        system[(i, i)] = 1.0;
    }
    for &(p, q, v) in &a {
        for i in 0..n {
            system[(i, q)] -= z[(i, p)] * v;
        }
    }
    system
        .view_mut((0, n), (n, m))
        .copy_from(&(-(&z * c.transpose())));
    system.view_mut((n, 0), (m, n)).copy_from(&g);
    let rhs = DVector::from_fn(n + m, |i, _| {
        if i < n {
            let h0r = solver.solution_entry(&w, equations[i]);
            match &weighted_residual {
                Some(mp) => h0r + w_at[i].dot(mp),
                None => h0r,
            }
        } else {
            -rows.gaps[i - n]
        }
    });
    let solution = system
        .lu()
        .solve(&rhs)
        .ok_or_else(|| StepFailure(REDUNDANT.into()))?;
    let (q, tau) = (solution.rows(0, n), solution.rows(n, m));
    let mut load = c.transpose() * tau;
    for &(p, column, v) in &a {
        load[p] += v * q[column];
    }
    for (eq, f) in equations.iter().zip(load.iter()) {
        solver.add_unit(&mut w, *eq, *f);
    }
    profile::add(Phase::Contact, schur_start);
    let delta = backward(solver, w, secant, projected_residual, (&w_at, load.iter()));
    Ok((delta, tau.iter().copied().collect()))
}
