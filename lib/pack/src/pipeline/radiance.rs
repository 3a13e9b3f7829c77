//! The traced radiance a surface layer is solved for, and the views of a view-independent
//! sample read one at a time as the solve asks ([`super::surface`], [`super::filter_choice`]).

use std::borrow::Cow;

use pis_compile::{CompileError, View, ViewSource};

use super::model::{PointView, Views};

/// The traced radiance a layer is solved for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Radiance {
    /// The diffuse layer: view-independent, its views stacked (eq. 3.7).
    Diffuse,
    Specular,
    /// Diffuse + specular (`--layers combined`).
    Sum,
    /// A translucent object's opacity (in every channel), solved with its first layer.
    Alpha,
}

impl Radiance {
    /// b at the covered pixels of `v`.
    pub fn at(self, v: &PointView) -> Cow<'_, [f32]> {
        match self {
            Radiance::Diffuse => Cow::Borrowed(&v.diffuse),
            Radiance::Specular => Cow::Borrowed(&v.specular),
            Radiance::Sum => {
                Cow::Owned(v.diffuse.iter().zip(&v.specular).map(|(d, s)| d + s).collect())
            }
            Radiance::Alpha => Cow::Borrowed(&v.alpha),
        }
    }
}

/// The views of a view-independent sample: its points' render matrices for one placement
/// and their radiance, each read (from the scratch file when the pack streams) as the solve
/// asks for it.
pub struct SampleViews<'a> {
    pub views: &'a Views,
    pub points: &'a [usize],
    pub placement: usize,
    pub radiance: Radiance,
}

impl ViewSource for SampleViews<'_> {
    fn count(&self) -> usize {
        self.points.len()
    }

    fn visit(
        &self,
        k: usize,
        f: &mut dyn FnMut(View<'_>) -> Result<(), CompileError>,
    ) -> Result<(), CompileError> {
        let v =
            self.views.get(self.points[k]).map_err(|e| CompileError::Source(format!("{e:#}")))?;
        let b = self.radiance.at(&v);
        f(View { a: v.a(self.placement), b: &b })
    }
}
