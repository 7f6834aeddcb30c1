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
    let roots: Vec<usize> = (0..m).map(|i| root(&mut parent, i)).collect();
    let mut order: Vec<usize> = (0..m).collect();
    order.sort_unstable_by_key(|&i| (roots[i], i));
    let mut mu = vec![0.0; m];
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
    for members in order.chunk_by(|a, b| roots[*a] == roots[*b]) {
        // a row alone (each slave on a rigid wall): the LU of its 1 x 1 group is the division
        // (the same bits), without the matrices' allocations
        if let [i] = *members {
            let diagonal = w(i, i);
            if diagonal != 0.0 {
                mu[i] = -violations[i] / diagonal;
            }
            continue;
        }
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

#[cfg(test)]
mod tests {
    use super::lumped_multipliers;

    /// Goal: each group of rows linked by a shared DOF is solved on its own, a row alone by
    /// its division, a singular group left at zero. Setup: five rows on six DOFs (inverse
    /// masses 2, 1, 4, 0, 1, 3): row 0 alone on DOF 0; rows 1 and 2 share DOF 2; row 3 on the
    /// prescribed DOF 3 (no multiplier moves it); row 4 alone on DOFs 4 and 5. Reference (by
    /// hand): mu_0 = -0.2 / 2; rows 1-2: [[5, -4], [-4, 4]] mu = [0.1, -0.3], mu = (-0.2,
    /// -0.275); mu_3 = 0; row 4: W = 0.25 + 0.75 = 1, mu_4 = -0.4. Tolerance 1e-14: a few
    /// operations on O(1) numbers.
    #[test]
    fn groups_are_solved_apart_and_a_singular_one_is_left() {
        let rows = vec![
            vec![(0, 1.0)],
            vec![(1, 1.0), (2, -1.0)],
            vec![(2, 1.0)],
            vec![(3, 1.0)],
            vec![(4, 0.5), (5, 0.5)],
        ];
        let violations = [0.2, -0.1, 0.3, 0.5, 0.4];
        let inverse_mass = [2.0, 1.0, 4.0, 0.0, 1.0, 3.0];
        let mu = lumped_multipliers(&rows, &violations, &inverse_mass);
        let exact = [-0.1, -0.2, -0.275, 0.0, -0.4];
        for (got, want) in mu.iter().zip(exact) {
            assert!((got - want).abs() < 1e-14, "{mu:?} against {exact:?}");
        }
    }
}
