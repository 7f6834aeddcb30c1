//! The gap of a slave node and its constraint rows (Hughes et al. 1975, II-13..16; legend
//! in `contact`).

/// A slave node's relation to its master at a given configuration.
#[derive(Debug, Clone, PartialEq)]
pub struct Gap {
    pub gap: f64,
    pub normal: [f64; 2],
    /// Master nodes and their weights (empty for a rigid obstacle).
    pub masters: Vec<(usize, f64)>,
    /// The slave-side nodes and weights of a weighted (mortar) gap: the slave node with the
    /// share of its support that a master covers; empty: the slave node alone, weight 1.
    pub spread: Vec<(usize, f64)>,
}

impl Gap {
    /// The slave-side nodes of the gap and their weights: `slave` alone, or the mortar
    /// spread.
    fn slave_side(&self, slave: usize) -> Vec<(usize, f64)> {
        if self.spread.is_empty() {
            vec![(slave, 1.0)]
        } else {
            self.spread.clone()
        }
    }

    /// The constraint row as (DOF, coefficient) pairs for slave node `slave`.
    pub fn row(&self, slave: usize) -> Vec<(usize, f64)> {
        let n = self.normal;
        let mut row = Vec::with_capacity(2 * (self.masters.len() + self.spread.len() + 1));
        for (s, w) in self.slave_side(slave) {
            row.push((2 * s, w * n[0]));
            row.push((2 * s + 1, w * n[1]));
        }
        for (m, w) in &self.masters {
            row.push((2 * m, -w * n[0]));
            row.push((2 * m + 1, -w * n[1]));
        }
        row
    }

    /// The tangent t = (-n_y, n_x): the direction of positive slip.
    pub fn tangent(&self) -> [f64; 2] {
        [-self.normal[1], self.normal[0]]
    }

    /// The tangential row t . (x_s - sum w_m x_m) as (DOF, coefficient) pairs: applied to an
    /// increment it gives the relative slip of the slave along the master.
    pub fn tangent_row(&self, slave: usize) -> Vec<(usize, f64)> {
        let t = self.tangent();
        let mut row = Vec::with_capacity(2 * (self.masters.len() + self.spread.len() + 1));
        for (s, w) in self.slave_side(slave) {
            row.push((2 * s, w * t[0]));
            row.push((2 * s + 1, w * t[1]));
        }
        for (m, w) in &self.masters {
            row.push((2 * m, -w * t[0]));
            row.push((2 * m + 1, -w * t[1]));
        }
        row
    }
}
