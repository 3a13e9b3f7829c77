//! The seam between pis-pack and the ways it can store an object. A [`Representation`] is
//! one of them: parameterized surface textures (thesis ch. 3, [`super::surface`]), layered
//! environment-map shells (ch. 5, [`super::pem`]) and lens objects (ch. 6, [`super::hybrid`]),
//! each a module behind this trait and one line of [`super::registry`]. The pack chooses a representation per object, then runs its three
//! steps over every object in turn: [`Representation::survey`] (what the object covers and
//! needs over the set's views), [`Surveyed::plan`] (its layers' parameter blocks, with the
//! block origins the pack staggers across objects, and the render matrices the solve reads),
//! [`Planned::solve`] (the layers' samples). The result, an [`ObjectModel`], is coded by the
//! same pyramids, storage allocation and codecs whatever made it.

use anyhow::Result;
use pis_compile::SolveSettings;
use pis_format::{DepMask, DimensionKind};
use pis_scene::ObjectRole;

use super::input::LoadedSet;
use super::matrices::Matrices;
use super::mesh::{merged_mesh, Mesh};
use super::model::ObjectModel;
use super::plan::Plan;
use super::{PackRequest, Progress};

/// A way to store an object and draw it.
pub trait Representation: Sync {
    /// The name the report gives.
    fn name(&self) -> &'static str;
    /// Whether it can store an object of `role`.
    fn applies(&self, role: ObjectRole) -> bool;
    /// Whether it stores an object as environment-map shells (used only where the
    /// representation mode asks for shells, [`super::registry::choose`]).
    fn shells(&self) -> bool {
        false
    }
    /// Object `o` over the set's views: `None` when nothing of it is to be stored (a note
    /// says why).
    fn survey(&self, job: &mut Job<'_>, o: usize) -> Result<Option<Box<dyn Surveyed>>>;
}

/// An object surveyed by its representation.
pub trait Surveyed {
    /// Places the layers' parameter blocks, their origins offset by `stagger` (thesis 4.7),
    /// and measures the render matrices the solve reads.
    fn plan(self: Box<Self>, job: &mut Job<'_>, stagger: Vec<u32>) -> Result<Box<dyn Planned>>;
}

/// An object with its layers planned.
pub trait Planned {
    /// Solves every layer sample.
    fn solve(self: Box<Self>, job: &Job<'_>) -> Result<ObjectModel>;
}

/// What every representation works with: the set and the request, the render-matrix
/// source, every object's mesh (each occludes the others), the container's parameter space
/// and blocks, the solver's settings; and the counts the pack reports.
pub struct Job<'a> {
    pub set: &'a LoadedSet,
    pub req: &'a PackRequest,
    /// The blocks, the container's parameter space and the staggering, resolved once.
    pub plan: &'a Plan,
    pub matrices: &'a mut Matrices,
    pub progress: &'a dyn Progress,
    pub meshes: Vec<Mesh>,
    /// Every dimension, and the dimensions that are not a view.
    pub all: DepMask,
    pub non_view: DepMask,
    pub settings: SolveSettings,
    /// Where the solves go: the solver, or a sharded pack's store of solutions.
    pub solver: crate::solutions::Solver,
    /// Texture placements made, and render matrices measured beyond one per object and point.
    pub placements: usize,
    pub extra_matrices: usize,
}

impl<'a> Job<'a> {
    pub fn new(
        set: &'a LoadedSet,
        req: &'a PackRequest,
        plan: &'a Plan,
        matrices: &'a mut Matrices,
        progress: &'a dyn Progress,
    ) -> Self {
        let scene = &set.scene;
        let meshes: Vec<Mesh> = (0..scene.objects.len()).map(|o| merged_mesh(scene, o)).collect();
        for (object, mesh) in scene.objects.iter().zip(&meshes) {
            if let Some(note) = &mesh.recharted {
                progress.note(&format!("object {}: {note}", object.name));
            }
        }
        let ndims = scene.space.dims.len();
        let view_dims: Vec<usize> = scene
            .space
            .dims
            .iter()
            .enumerate()
            .filter(|(_, d)| d.kind == DimensionKind::View)
            .map(|(k, _)| k)
            .collect();
        let all = DepMask::of(&(0..ndims).collect::<Vec<_>>());
        let non_view =
            DepMask::of(&(0..ndims).filter(|k| !view_dims.contains(k)).collect::<Vec<_>>());
        // Level 0 solved through the MIP chain the player decimates from it (thesis 3.6): the
        // solved textures are the drawn ones.
        let mut settings = SolveSettings::decimated();
        if let Some(n) = req.max_iterations {
            settings.cg.max_iterations = n.max(1);
        }
        Job {
            set,
            req,
            plan,
            matrices,
            progress,
            meshes,
            all,
            non_view,
            settings,
            solver: req.solver.clone(),
            placements: 0,
            extra_matrices: 0,
        }
    }

    /// A note on the work.
    pub fn note(&self, text: &str) {
        self.progress.note(text);
    }
}
