//! The force passes as a step feature: the surface (body) terms' face, body,
//! edge and node passes and their gathers ([`super::surface`]), the volume
//! elements' pass ([`super::tetra`]), then the pair, bonded and external
//! forces of every particle (shaders/common/forces.wgsl), which read the
//! surface and element slots. Which of them run follows the packed layout's
//! offsets, read at each encoding (bond kinetics on the host repack them).

use super::step::{Dispatcher, Over, Phase, StepFeature};

/// The force passes' kernels.
pub(super) struct ForcePasses {
    faces: wgpu::ComputePipeline,
    bodies: wgpu::ComputePipeline,
    edges: wgpu::ComputePipeline,
    nodes: wgpu::ComputePipeline,
    edge_forces: wgpu::ComputePipeline,
    surface_forces: wgpu::ComputePipeline,
    tetra_forces: wgpu::ComputePipeline,
    forces: wgpu::ComputePipeline,
}

impl ForcePasses {
    pub(super) fn new(pipeline: impl Fn(&str) -> wgpu::ComputePipeline) -> Self {
        Self {
            faces: pipeline("surface_faces"),
            bodies: pipeline("surface_bodies"),
            edges: pipeline("surface_edges"),
            nodes: pipeline("surface_nodes"),
            edge_forces: pipeline("surface_edge_forces"),
            surface_forces: pipeline("surface_forces"),
            tetra_forces: pipeline("tetra_forces"),
            forces: pipeline("forces"),
        }
    }

    /// The kernels in order under the layout of `at` (the surface passes
    /// none without surface terms, the curvature passes only with a
    /// curvature law; the volume elements' none without elements).
    pub(super) fn passes(&self, at: &Dispatcher) -> Vec<(&wgpu::ComputePipeline, Over)> {
        let [faces, bodies, edges, nodes] = [12, 13, 14, 15].map(|c| at.params.surface_offsets[c]);
        let mut passes = Vec::new();
        if faces > 0 {
            passes.extend([(&self.faces, Over::each(faces)), (&self.bodies, Over::Groups(bodies))]);
            if edges > 0 {
                passes.extend([(&self.edges, Over::each(edges)), (&self.nodes, Over::each(nodes)), (&self.edge_forces, Over::each(edges))]);
            }
            passes.push((&self.surface_forces, Over::each(faces)));
        }
        if at.params.tetra_offsets[5] > 0 {
            passes.push((&self.tetra_forces, Over::each(at.params.tetra_offsets[5])));
        }
        passes.push((&self.forces, Over::Chunks));
        passes
    }
}

impl StepFeature for ForcePasses {
    fn encode(&self, phase: Phase, at: &Dispatcher, pass: &mut wgpu::ComputePass) {
        if phase == Phase::Forces {
            at.dispatch_all(pass, &self.passes(at));
        }
    }
}
