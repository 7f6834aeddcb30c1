//! The gap of a slave node and its constraint rows (Hughes et al. 1975, II-13..16; legend
//! in `contact`).

/// A slave node's relation to its master at a given configuration.
#[derive(Debug, Clone, PartialEq)]
pub struct Gap {
    pub gap: f64,
    pub normal: [f64; 2],
    /// Master nodes and their weights (empty for a rigid obstacle).
    pub masters: Vec<(usize, f64)>,
    /// The slave node's weight: 1, or for a weighted (mortar) gap the share of its support
    /// that a master covers (the master weights sum to it).
    pub weight: f64,
    /// A rotating projectile's spin node and the slave's arm r from the projectile's centre:
    /// the rotation theta (the node's first DOF) moves the obstacle's point under the slave
    /// by theta e_z x r, so a row along d holds -(r x d) on it (None elsewhere).
    pub lever: Option<(usize, [f64; 2])>,
}

impl Gap {
    /// The constraint row as (DOF, coefficient) pairs for slave node `slave`.
    pub fn row(&self, slave: usize) -> Vec<(usize, f64)> {
        self.row_along(slave, self.normal)
    }

    /// The tangent t = (-n_y, n_x): the direction of positive slip.
    pub fn tangent(&self) -> [f64; 2] {
        [-self.normal[1], self.normal[0]]
    }

    /// The tangential row t . (w x_s - sum w_m x_m) as (DOF, coefficient) pairs: applied to
    /// an increment it gives the relative slip of the slave along the master.
    pub fn tangent_row(&self, slave: usize) -> Vec<(usize, f64)> {
        self.row_along(slave, self.tangent())
    }

    /// d . (w x_s - sum w_m x_m) as (DOF, coefficient) pairs.
    fn row_along(&self, slave: usize, d: [f64; 2]) -> Vec<(usize, f64)> {
        let w = self.weight;
        let mut row = Vec::with_capacity(2 * (self.masters.len() + 1));
        row.push((2 * slave, w * d[0]));
        row.push((2 * slave + 1, w * d[1]));
        for (m, w) in &self.masters {
            row.push((2 * m, -w * d[0]));
            row.push((2 * m + 1, -w * d[1]));
        }
        if let Some((spin, r)) = self.lever {
            row.push((2 * spin, -(r[0] * d[1] - r[1] * d[0])));
        }
        row
    }
}
