//! The KKT solve by static condensation ([`LinearSolverKind::Condensed`]): coordinate blocks
//! that couple only to the rest of the system (each fluid of a fluid vehicle couples only to
//! its tank body) are factored on their own, and the rest is solved through its Schur
//! complement.
//!
//! With the blocks `I_k` and the rest `O` (rigid coordinates and Lagrange multipliers),
//!
//! ```text
//! [ A_kk  B_k ] [x_k]   [b_k]      S = A_OO − Σ_k C_k A_kk⁻¹ B_k
//! [ C_k   A_OO] [x_O] = [b_O]      x_O = S⁻¹ (b_O − Σ_k C_k A_kk⁻¹ b_k),  x_k = A_kk⁻¹ (b_k − B_k x_O)
//! ```
//!
//! `B_k` has as many columns as `I_k` has coupled outer coordinates (the 7 coordinates of the
//! tank body), so `X_k = A_kk⁻¹ B_k` costs 7 solves and the update of `S` is a dense 7 × 7
//! block. This is the same linear algebra as one LU of the whole matrix, in exact arithmetic,
//! without the fill that a column ordering of the coupled matrix creates between the fluids.
//! The blocks are factored and solved in parallel, each sequentially, and their contributions
//! to the rest are added in block order, so the results do not depend on the thread count.
//!
//! [`LinearSolverKind::Condensed`]: super::LinearSolverKind::Condensed

use std::ops::Range;

use faer::sparse::{Pair, SparseColMat, SparseColMatRef, SymbolicSparseColMat};
use rayon::prelude::*;

use super::linear_solver::{LinearFailure, LinearSolver, SparseLu};

const NONE: usize = usize::MAX;

/// A sparse LU of a sub-matrix gathered from the full matrix's values.
struct SubLu {
    matrix: SparseColMat<usize, f64>,
    /// (value position in `matrix`, value position in the full matrix).
    gather: Vec<(usize, usize)>,
    lu: SparseLu,
    /// Full-matrix index of each sub-matrix row and column (for error messages).
    global: Vec<usize>,
}

impl SubLu {
    /// `entries`: (row, col) of the sub-matrix (diagonal included by the caller).
    fn new(dim: usize, entries: &[(usize, usize)], global: Vec<usize>) -> Result<Self, LinearFailure> {
        let pairs: Vec<Pair<usize, usize>> = entries.iter().map(|&(row, col)| Pair { row, col }).collect();
        let (symbolic, _) =
            SymbolicSparseColMat::try_new_from_indices(dim, dim, &pairs).map_err(LinearFailure::generic)?;
        let nnz = symbolic.row_idx().len();
        let matrix = SparseColMat::new(symbolic, vec![0.0; nnz]);
        let lu = SparseLu::new(matrix.symbolic())?;
        Ok(Self { matrix, gather: Vec::new(), lu, global })
    }

    /// Value position of (row, col), which must be in the pattern.
    fn pos(&self, row: usize, col: usize) -> usize {
        let sym = self.matrix.symbolic();
        let start = sym.col_ptr()[col];
        let rows = &sym.row_idx()[start..sym.col_ptr()[col + 1]];
        start + rows.binary_search(&row).expect("entry in the sub-matrix pattern")
    }

    /// Gathers the values from the full matrix (the Schur complement adds its update after).
    fn gather_from(&mut self, full: &[f64]) {
        let vals = self.matrix.val_mut();
        vals.fill(0.0);
        for &(p, q) in &self.gather {
            vals[p] += full[q];
        }
    }

    fn factor(&mut self) -> Result<(), LinearFailure> {
        if self.matrix.val().iter().any(|v| !v.is_finite()) {
            return Err(LinearFailure::Numeric(None));
        }
        self.lu.factor(self.matrix.as_ref()).map_err(|e| match e {
            LinearFailure::NoPivot(i) => LinearFailure::NoPivot(self.global.get(i).copied().unwrap_or(i)),
            other => other,
        })
    }

    /// Solves in place for the `ncols` columns of `x` (column-major, `dim` rows).
    fn solve(&mut self, x: &mut [f64], ncols: usize) -> Result<(), LinearFailure> {
        self.lu.solve(x, ncols)
    }
}

/// One condensed block `I_k`.
struct Block {
    range: Range<usize>,
    lu: SubLu,
    /// Outer positions of the columns of `B_k` and of the rows of `C_k`.
    cols: Vec<usize>,
    rows: Vec<usize>,
    /// `B_k` entries: (local row, column index into `cols`, full value position).
    b: Vec<(usize, usize, usize)>,
    /// `C_k` entries: (row index into `rows`, local column, full value position).
    c: Vec<(usize, usize, usize)>,
    /// Schur value position of each (row in `rows`, column in `cols`), row-major.
    s_pos: Vec<usize>,
    /// `X_k = A_kk⁻¹ B_k`, column-major, and the solve buffer `y_k`.
    x: Vec<f64>,
    y: Vec<f64>,
    /// `C_k` values at the last factorization (sparse, in `c` order).
    c_val: Vec<f64>,
    /// `C_k X_k`, row-major |rows| × |cols|.
    update: Vec<f64>,
}

/// The condensed KKT solver.
pub(crate) struct Condensed {
    blocks: Vec<Block>,
    /// Full index of each outer unknown.
    outer: Vec<usize>,
    schur: SubLu,
    /// Outer right-hand side buffer.
    bo: Vec<f64>,
}

impl Condensed {
    /// Builds the partition from the full matrix's CSC pattern (`col_ptr`, `row_idx`) and the
    /// block ranges; errors when a block couples to another block or the ranges overlap.
    pub(crate) fn new(
        dim: usize,
        col_ptr: &[usize],
        row_idx: &[usize],
        ranges: &[Range<usize>],
    ) -> Result<Self, LinearFailure> {
        let mut block_of = vec![NONE; dim];
        for (k, r) in ranges.iter().enumerate() {
            if r.end > dim || r.is_empty() {
                return Err(LinearFailure::Generic(format!("condensed block {k} = {r:?} outside 0..{dim} or empty")));
            }
            for i in r.clone() {
                if block_of[i] != NONE {
                    return Err(LinearFailure::Generic(format!("condensed blocks overlap at unknown {i}")));
                }
                block_of[i] = k;
            }
        }
        let outer: Vec<usize> = (0..dim).filter(|&i| block_of[i] == NONE).collect();
        let mut outer_of = vec![NONE; dim];
        for (o, &i) in outer.iter().enumerate() {
            outer_of[i] = o;
        }
        let nb = ranges.len();
        let mut inner_entries: Vec<Vec<(usize, usize, usize)>> = vec![Vec::new(); nb];
        let mut b_raw: Vec<Vec<(usize, usize, usize)>> = vec![Vec::new(); nb]; // (local row, outer col, pos)
        let mut c_raw: Vec<Vec<(usize, usize, usize)>> = vec![Vec::new(); nb]; // (outer row, local col, pos)
        let mut outer_entries: Vec<(usize, usize, usize)> = Vec::new();
        for j in 0..dim {
            for (p, &i) in row_idx.iter().enumerate().take(col_ptr[j + 1]).skip(col_ptr[j]) {
                match (block_of[i], block_of[j]) {
                    (NONE, NONE) => outer_entries.push((outer_of[i], outer_of[j], p)),
                    (ki, NONE) => b_raw[ki].push((i - ranges[ki].start, outer_of[j], p)),
                    (NONE, kj) => c_raw[kj].push((outer_of[i], j - ranges[kj].start, p)),
                    (ki, kj) if ki == kj => {
                        let s = ranges[ki].start;
                        inner_entries[ki].push((i - s, j - s, p));
                    }
                    (ki, kj) => {
                        return Err(LinearFailure::Generic(format!(
                            "condensed blocks {ki} and {kj} are coupled at ({i}, {j})"
                        )));
                    }
                }
            }
        }
        let mut blocks = Vec::with_capacity(nb);
        let mut schur_entries: Vec<(usize, usize)> = outer_entries.iter().map(|&(r, c, _)| (r, c)).collect();
        schur_entries.extend((0..outer.len()).map(|o| (o, o)));
        for k in 0..nb {
            let r = ranges[k].clone();
            let n = r.len();
            let mut entries: Vec<(usize, usize)> = inner_entries[k].iter().map(|&(a, b, _)| (a, b)).collect();
            entries.extend((0..n).map(|a| (a, a)));
            let mut lu = SubLu::new(n, &entries, r.clone().collect())?;
            lu.gather = inner_entries[k].iter().map(|&(a, b, p)| (lu.pos(a, b), p)).collect();
            let mut cols: Vec<usize> = b_raw[k].iter().map(|e| e.1).collect();
            cols.sort_unstable();
            cols.dedup();
            let mut rows: Vec<usize> = c_raw[k].iter().map(|e| e.0).collect();
            rows.sort_unstable();
            rows.dedup();
            let b = b_raw[k].iter().map(|&(a, o, p)| (a, cols.binary_search(&o).expect("column"), p)).collect();
            let c: Vec<(usize, usize, usize)> =
                c_raw[k].iter().map(|&(o, a, p)| (rows.binary_search(&o).expect("row"), a, p)).collect();
            for &ro in &rows {
                for &co in &cols {
                    schur_entries.push((ro, co));
                }
            }
            let nc = c.len();
            blocks.push(Block {
                range: r,
                lu,
                x: vec![0.0; n * cols.len()],
                y: vec![0.0; n],
                c_val: vec![0.0; nc],
                update: vec![0.0; rows.len() * cols.len()],
                s_pos: Vec::new(),
                cols,
                rows,
                b,
                c,
            });
        }
        let mut schur = SubLu::new(outer.len(), &schur_entries, outer.clone())?;
        schur.gather = outer_entries.iter().map(|&(r, c, p)| (schur.pos(r, c), p)).collect();
        for b in &mut blocks {
            b.s_pos = b
                .rows
                .iter()
                .flat_map(|&ro| b.cols.iter().map(move |&co| (ro, co)))
                .map(|(r, c)| schur.pos(r, c))
                .collect();
        }
        let bo = vec![0.0; outer.len()];
        Ok(Self { blocks, outer, schur, bo })
    }

    /// Factors every block (in parallel: they are independent, and each is factored
    /// sequentially, so the results do not depend on the thread count), forms `X_k` and the
    /// Schur complement (updates subtracted in block order), and factors it.
    fn factor_values(&mut self, full: &[f64]) -> Result<(), LinearFailure> {
        self.schur.gather_from(full);
        self.blocks.par_iter_mut().try_for_each(|blk| blk.factor(full))?;
        let vals = self.schur.matrix.val_mut();
        for blk in &self.blocks {
            for (u, &p) in blk.update.iter().zip(&blk.s_pos) {
                vals[p] -= u;
            }
        }
        self.schur.factor()
    }

    /// Solves `A x = b` in place with the factors of the last [`Self::factor_values`].
    fn solve_one(&mut self, x: &mut [f64]) -> Result<(), LinearFailure> {
        for (o, &i) in self.outer.iter().enumerate() {
            self.bo[o] = x[i];
        }
        let rhs: &[f64] = x;
        self.blocks.par_iter_mut().try_for_each(|blk| {
            blk.y.copy_from_slice(&rhs[blk.range.clone()]);
            blk.lu.solve(&mut blk.y, 1)
        })?;
        for blk in &self.blocks {
            for (&(ri, a, _), &cv) in blk.c.iter().zip(&blk.c_val) {
                self.bo[blk.rows[ri]] -= cv * blk.y[a];
            }
        }
        self.schur.solve(&mut self.bo, 1)?;
        for (o, &i) in self.outer.iter().enumerate() {
            x[i] = self.bo[o];
        }
        for blk in &mut self.blocks {
            let n = blk.range.len();
            let xk = &mut x[blk.range.clone()];
            xk.copy_from_slice(&blk.y);
            for (j, &co) in blk.cols.iter().enumerate() {
                let xo = self.bo[co];
                for (xa, &x) in xk.iter_mut().zip(&blk.x[n * j..n * (j + 1)]) {
                    *xa -= x * xo;
                }
            }
        }
        Ok(())
    }
}

impl LinearSolver for Condensed {
    fn factor(&mut self, matrix: SparseColMatRef<'_, usize, f64>) -> Result<(), LinearFailure> {
        self.factor_values(matrix.val())
    }

    fn solve(&mut self, x: &mut [f64], ncols: usize) -> Result<(), LinearFailure> {
        let dim = x.len() / ncols.max(1);
        x.chunks_mut(dim.max(1)).try_for_each(|col| self.solve_one(col))
    }
}

impl Block {
    /// Numeric LU of `A_kk`, `X_k = A_kk⁻¹ B_k`, and this block's Schur update `C_k X_k`.
    fn factor(&mut self, full: &[f64]) -> Result<(), LinearFailure> {
        self.lu.gather_from(full);
        self.lu.factor()?;
        let n = self.range.len();
        let ncols = self.cols.len();
        self.x.fill(0.0);
        for &(a, j, p) in &self.b {
            self.x[a + n * j] += full[p];
        }
        if ncols > 0 {
            self.lu.solve(&mut self.x, ncols)?;
        }
        for (v, &(_, _, p)) in self.c_val.iter_mut().zip(&self.c) {
            *v = full[p];
        }
        self.update.fill(0.0);
        for (&(ri, a, _), &cv) in self.c.iter().zip(&self.c_val) {
            for j in 0..ncols {
                self.update[ri * ncols + j] += cv * self.x[a + n * j];
            }
        }
        Ok(())
    }
}
