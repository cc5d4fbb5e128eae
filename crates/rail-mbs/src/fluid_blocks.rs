//! Where an ANCF fluid body sits in a system's sparse matrices: one 12×12 block for every pair
//! of nodes that share an element, the fluid's coordinates starting at an offset. The slosh
//! system ([`crate::slosh::SloshSystem`]) and the fluid vehicle
//! ([`crate::vehicle::FluidVehicle`]) both lay their fluids out and assemble the element
//! Jacobians through it, and take the default penetration limit from here.

use std::collections::HashMap;

use ancf_core::FluidBody;
use ancf_core::body::ElementJacobian;
use ancf_core::shape::N_SHAPE;

use crate::integrator::SystemError;

/// Default penetration limit relative to the smallest element edge: a contact point
/// half an element deep in the wall means the penalty contact no longer represents
/// the wall.
pub const PENETRATION_LIMIT_FACTOR: f64 = 0.5;

/// The default penetration (and containment) limit of `body`: [`PENETRATION_LIMIT_FACTOR`]
/// × its smallest element edge, m.
pub fn default_penetration_limit(body: &FluidBody) -> f64 {
    PENETRATION_LIMIT_FACTOR * body.elements.iter().flat_map(|e| e.lengths).fold(f64::INFINITY, f64::min)
}

/// The node-pair blocks of one fluid body in a sparsity pattern.
#[derive(Debug, Clone, Default)]
pub struct FluidBlocks {
    /// Pattern index of the 12×12 block of each node pair (row node, column node).
    pub blocks: HashMap<(usize, usize), usize>,
    /// Per element: the pattern starts of its 64 node-pair blocks (row node × 8 + column node).
    pub element_blocks: Vec<[usize; 64]>,
}

impl FluidBlocks {
    /// Appends the blocks of `body`, whose coordinates start at `offset`, to `pattern`
    /// (row-major within each block) and returns where they went.
    pub fn append(body: &FluidBody, offset: usize, pattern: &mut Vec<(usize, usize)>) -> Self {
        let mut out = Self { blocks: HashMap::new(), element_blocks: Vec::with_capacity(body.mesh.n_elements()) };
        for nodes in &body.mesh.elements {
            let mut eb = [0usize; 64];
            for (i, &ni) in nodes.iter().enumerate() {
                for (j, &nj) in nodes.iter().enumerate() {
                    let start = *out.blocks.entry((ni, nj)).or_insert_with(|| {
                        let s = pattern.len();
                        for r in 0..12 {
                            for c in 0..12 {
                                pattern.push((offset + 12 * ni + r, offset + 12 * nj + c));
                            }
                        }
                        s
                    });
                    eb[8 * i + j] = start;
                }
            }
            out.element_blocks.push(eb);
        }
        out
    }

    /// Pattern index of the entry (`row`, `col`) in the fluid's own coordinates.
    #[inline]
    pub fn value_index(&self, row: usize, col: usize) -> usize {
        self.blocks[&(row / 12, col / 12)] + (row % 12) * 12 + col % 12
    }

    /// Pattern index of entry (compact 3a + i, compact 3b + k) of an element whose node-pair
    /// blocks start at `eb`.
    #[inline]
    pub fn element_index(eb: &[usize; 64], a: usize, i: usize, b: usize, k: usize) -> usize {
        eb[8 * (a / 4) + b / 4] + (3 * (a % 4) + i) * 12 + 3 * (b % 4) + k
    }

    /// Subtracts every element's exact Jacobians `∂f/∂e`, `∂f/∂ė` (internal forces enter
    /// `Q` with a minus sign) from the pattern values `dq`, `dv`; `jacs` is a reused buffer.
    pub fn subtract_element_jacobians(
        &self,
        body: &FluidBody,
        e: &[f64],
        edot: &[f64],
        dq: &mut [f64],
        dv: &mut [f64],
        jacs: &mut Vec<ElementJacobian>,
    ) -> Result<(), SystemError> {
        body.element_jacobians_into(e, edot, jacs)?;
        for (el, jac) in jacs.iter().enumerate() {
            let eb = &self.element_blocks[el];
            for a in 0..N_SHAPE {
                for b in 0..N_SHAPE {
                    for i in 0..3 {
                        let row = 96 * (3 * a + i);
                        for k in 0..3 {
                            let idx = Self::element_index(eb, a, i, b, k);
                            dq[idx] -= jac.stiffness[row + 3 * b + k];
                            dv[idx] -= jac.damping[row + 3 * b + k];
                        }
                    }
                }
            }
        }
        Ok(())
    }
}
