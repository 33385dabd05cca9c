//! The implicit step's conjugate gradients over every workgroup: the split
//! solve (kernels and their order: shaders/common/implicit_split.wgsl).
//!
//! The one-workgroup solve (`implicit_solve`) keeps its loop on the device,
//! so a step costs no read-back, but it runs on one compute unit. The split
//! solve runs each phase of an iteration as a dispatch over every workgroup
//! (product, α, update, β and direction), which a command buffer can only
//! hold a fixed number of: the host encodes a **budget** of iterations per
//! step, and the kernels after convergence return at once. A step whose
//! solve has not converged when the budget runs out halts with HALT_BUDGET
//! before it moves anything; the host doubles the budget (up to
//! `max_iterations`) and takes that step again from the same state, so the
//! run's bits do not depend on the budget. After each run the budget is
//! fitted to twice the most iterations a step took (a power of two, at least
//! [`LEAST_BUDGET`]), so a quiet stretch does not keep paying for one hard step.
//!
//! Its sums differ from the one-workgroup solve's in their order (per
//! workgroup, then over workgroups), so its bits differ from it by f32
//! rounding; both are matched to the CPU in tests/suite/gpu_implicit.rs.

use super::context::GpuContext;
use super::side_group::SideGroup;

/// The first iteration budget per step, and the least the fitting leaves.
const FIRST_BUDGET: usize = 32;
const LEAST_BUDGET: usize = 8;

pub(super) struct SplitSolve {
    start: wgpu::ComputePipeline,
    /// With body terms: the bodies' and curvature nodes' dots before each product.
    body_dots: Option<wgpu::ComputePipeline>,
    product: wgpu::ComputePipeline,
    residual: wgpu::ComputePipeline,
    first: wgpu::ComputePipeline,
    alpha: wgpu::ComputePipeline,
    update: wgpu::ComputePipeline,
    direction: wgpu::ComputePipeline,
    finish: wgpu::ComputePipeline,
    /// With contact between bodies: the step clamp's minimum.
    clamp: Option<wgpu::ComputePipeline>,
    budget: Budget,
}

/// Iterations encoded per step (`budget`), and `max_iterations` (`cap`).
struct Budget {
    budget: usize,
    cap: usize,
}

impl Budget {
    fn grow(&mut self) {
        self.budget = (2 * self.budget).min(self.cap);
    }

    fn fit(&mut self, most: usize) {
        self.budget = (2 * most).next_power_of_two().max(LEAST_BUDGET).min(self.cap);
    }
}

impl SplitSolve {
    pub(super) fn new(side: &SideGroup, ctx: &GpuContext, bodies: bool, contact: bool, cap: usize) -> Self {
        let kernel = |name: &str| side.pipeline(ctx, &format!("implicit_split_{name}"));
        Self {
            start: kernel("start"),
            body_dots: bodies.then(|| kernel("body_dots")),
            product: kernel("product"),
            residual: kernel("residual"),
            first: kernel("first"),
            alpha: kernel("alpha"),
            update: kernel("update"),
            direction: kernel("direction"),
            finish: kernel("finish"),
            clamp: contact.then(|| kernel("clamp")),
            budget: Budget { budget: FIRST_BUDGET.min(cap), cap },
        }
    }

    /// One step's solve: its kernels in order with their workgroups, for
    /// `particle_groups` workgroups over the particles and `body_groups` over
    /// the bodies' curvature nodes and bodies.
    pub(super) fn passes(&self, particle_groups: u32, body_groups: u32) -> Vec<(&wgpu::ComputePipeline, u32)> {
        let product = |passes: &mut Vec<_>| {
            passes.extend(self.body_dots.as_ref().map(|k| (k, body_groups)));
            passes.push((&self.product, particle_groups));
        };
        let mut passes = vec![(&self.start, particle_groups)];
        product(&mut passes);
        passes.extend([(&self.residual, particle_groups), (&self.first, 1)]);
        for _ in 0..self.budget.budget {
            product(&mut passes);
            passes.extend([(&self.alpha, 1), (&self.update, particle_groups), (&self.direction, particle_groups)]);
        }
        passes.push((&self.finish, 1));
        passes.extend(self.clamp.as_ref().map(|k| (k, particle_groups)));
        passes
    }

    /// After a HALT_BUDGET: twice the budget, at most `max_iterations`.
    pub(super) fn grow(&mut self) {
        self.budget.grow();
    }

    /// After a run: twice the most iterations a step took, as a power of two
    /// of at least [`LEAST_BUDGET`], at most `max_iterations`.
    pub(super) fn fit(&mut self, most: usize) {
        self.budget.fit(most);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The budget doubles up to the cap and is fitted to twice the most
    /// iterations, a power of two within [LEAST_BUDGET, cap].
    #[test]
    fn the_budget_grows_to_the_cap_and_fits_the_work() {
        let budget = |cap: usize, most: Option<usize>, grows: usize| {
            let mut b = Budget { budget: FIRST_BUDGET.min(cap), cap };
            (0..grows).for_each(|_| b.grow());
            most.into_iter().for_each(|m| b.fit(m));
            b.budget
        };
        assert_eq!(budget(1000, None, 0), 32);
        assert_eq!(budget(1000, None, 2), 128);
        assert_eq!(budget(100, None, 3), 100);
        assert_eq!(budget(5, None, 0), 5);
        assert_eq!(budget(1000, Some(40), 0), 128);
        assert_eq!(budget(1000, Some(2), 0), LEAST_BUDGET);
        assert_eq!(budget(1000, Some(900), 0), 1000);
        assert_eq!(budget(5, Some(1), 0), 5);
    }
}
