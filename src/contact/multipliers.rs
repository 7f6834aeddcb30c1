//! Multipliers of constraint rows on the lumped mass, (C M^-1 C^T) mu = -g: the explicit
//! contact step's forward-increment multipliers (`explicit`) and the impact conditions of
//! mortar rows (`conditions`).

/// The multipliers mu of (C M^-1 C^T) mu = -g for constraint rows C
/// (lumped M), g the rows' `violations` (the gaps of normal rows, the slips of tangential
/// ones). C M^-1 C^T couples two rows only through a shared DOF, so it is solved per
/// group of rows linked by shared DOFs (one row each on a rigid wall; a run of slaves on a
/// shared master segment otherwise; on a deformable master a continuous contact zone is one
/// group, so the gain is on rigid obstacles): dense LU of the groups instead of the whole
/// m x m matrix. A singular group (redundant rows, or rows on prescribed DOFs only, which no
/// multiplier can move) gets mu = 0 and is left to the penetration check; the others are
/// solved.
pub(super) fn lumped_multipliers(
    rows: &[Vec<(usize, f64)>],
    violations: &[f64],
    inverse_mass: &[f64],
) -> Vec<f64> {
    let m = rows.len();
    // union-find of the rows over their DOFs
    let mut parent: Vec<usize> = (0..m).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    // (DOF, row) of the nonzero coefficients, sorted: each row joins the first row of its DOFs
    let mut uses: Vec<(usize, usize)> = rows
        .iter()
        .enumerate()
        .flat_map(|(i, row)| {
            row.iter()
                .filter(|(_, c)| *c != 0.0)
                .map(move |(dof, _)| (*dof, i))
        })
        .collect();
    uses.sort_unstable();
    let mut owner: Option<(usize, usize)> = None;
    for (dof, i) in uses {
        match owner {
            Some((d, j)) if d == dof => {
                let (a, b) = (root(&mut parent, i), root(&mut parent, j));
                parent[a] = b;
            }
            _ => owner = Some((dof, i)),
        }
    }
    let mut groups: std::collections::BTreeMap<usize, Vec<usize>> = Default::default();
    for i in 0..m {
        let r = root(&mut parent, i);
        groups.entry(r).or_default().push(i);
    }
    let mut mu = vec![0.0; m];
    for members in groups.values() {
        let w = |i: usize, j: usize| -> f64 {
            rows[i]
                .iter()
                .map(|(a, ca)| {
                    rows[j]
                        .iter()
                        .filter(|(b, _)| b == a)
                        .map(|(_, cb)| ca * cb * inverse_mass[*a])
                        .sum::<f64>()
                })
                .sum()
        };
        let k = members.len();
        let matrix = nalgebra::DMatrix::from_fn(k, k, |a, b| w(members[a], members[b]));
        let rhs = nalgebra::DVector::from_fn(k, |a, _| -violations[members[a]]);
        let Some(solution) = matrix.lu().solve(&rhs) else {
            continue;
        };
        for (a, &i) in members.iter().enumerate() {
            mu[i] = solution[a];
        }
    }
    mu
}
