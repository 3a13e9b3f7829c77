//! Layered, parameterized environment maps (thesis ch. 5): a reflective object's incident
//! specular light as two environment-map shells per parameter sample — a local shell, the
//! least-volume ellipsoid bounding the object, with alpha for the object's reflections of
//! itself, over a distant shell, a box on the supporting surface or a sphere, whichever
//! reproduces the traced distant layer better ([`fit`]), or a depth shell, one map over the
//! views, where it predicts a point between two samples better ([`between`]) — modulated by
//! the Fresnel factor the player evaluates from the object's F0; plus a diffuse surface
//! texture when the object has one ([`super::surface`]). Each shell's render matrix comes
//! from the hardware model's environment-map lookup ([`views`]); the cube maps are solved,
//! every MIP level together, against the tracer's local and distant layers ([`solve`]) and
//! stored whole ([`form`]).
//! The baselines of thesis 5.10 and 5.1 are made here too: one map at infinity per sample,
//! inferred (`single_shell`) or ray-traced from the object's centre ([`traced`]).

pub mod between;
pub mod budget;
pub mod fit;
pub mod form;
pub mod solve;
pub mod terms;
pub mod traced;
pub mod views;

use anyhow::Result;
use pis_compile::shell::Shell;
use pis_compile::{SolveSettings, TextureLayout};
use pis_scene::ObjectRole;
use pis_trace::layers::LayerKind as TraceLayer;

use super::model::{key, InferredLayer, ObjectModel};
use super::represent::{Job, Planned, Representation, Surveyed};
use super::surface::survey_surface;
use super::DistantShell;
use between::{between_error, held_out_points};
use fit::{fit_shells, is_depth, FittedShells};
use form::ShellForm;
use solve::{solve_shell, solve_shell_shared, SolvedShell, Target};
use terms::ReflectionTerms;
use views::{face_resolution, shell_views, ShellView, LARGEST_FACE};

/// The report's words for `--shell-lookups` above 1.
fn lookups_text(lookups: u32) -> String {
    if lookups > 1 {
        format!(", {lookups}×{lookups} lookups per pixel")
    } else {
        String::new()
    }
}

/// Layered environment maps: reflective objects whose set has the tracer's local and
/// distant layers.
pub struct LayeredPem;

impl Representation for LayeredPem {
    fn name(&self) -> &'static str {
        "layered environment maps"
    }

    fn shells(&self) -> bool {
        true
    }

    fn applies(&self, role: ObjectRole) -> bool {
        role == ObjectRole::Reflective
    }

    /// The object's surface part (its diffuse layer, if any, and every point's rows and gold
    /// standard) and its fitted shells; an object whose set lacks the local and distant
    /// layers is stored as surface textures.
    fn survey(&self, job: &mut Job<'_>, o: usize) -> Result<Option<Box<dyn Surveyed>>> {
        let set = job.set;
        let name = &set.scene.objects[o].name;
        if !layered(set, o) {
            job.note(&format!("object {name}: the set has no local and distant layers for it; stored as surface textures"));
            return survey_surface(job, o, true);
        }
        let Some(surface) = survey_surface(job, o, false)? else { return Ok(None) };
        // The depth shell's cube is cast only where `--distant-shell` may take it.
        let with_depth = matches!(
            job.req.distant_shell,
            DistantShell::Auto | DistantShell::Depth | DistantShell::DepthPerSample
        );
        let fitted = fit_shells(set, o, &job.meshes, with_depth)?;
        Ok(Some(Box::new(PemSurveyed { o, surface, fitted })))
    }
}

struct PemSurveyed {
    o: usize,
    surface: Box<dyn Surveyed>,
    fitted: FittedShells,
}

impl Surveyed for PemSurveyed {
    fn plan(self: Box<Self>, job: &mut Job<'_>, stagger: Vec<u32>) -> Result<Box<dyn Planned>> {
        let PemSurveyed { o, surface, fitted } = *self;
        let surface = surface.plan(job, stagger)?;
        Ok(Box::new(PemPlanned { o, surface, fitted }))
    }
}

struct PemPlanned {
    o: usize,
    surface: Box<dyn Planned>,
    fitted: FittedShells,
}

/// The shells chosen for an object, their layouts and solutions.
struct Chosen {
    shells: Vec<(Shell, TextureLayout, Target)>,
    views: Vec<ShellView>,
    solved: Vec<SolvedShell>,
    why: String,
}

impl Planned for PemPlanned {
    fn solve(self: Box<Self>, job: &Job<'_>) -> Result<ObjectModel> {
        let PemPlanned { o, surface, fitted } = *self;
        let mut model = surface.solve(job)?;
        let set = job.set;
        let f0 = super::shading::object_shading(&set.scene, o).f0;
        let pixels: Vec<Vec<u32>> = (0..model.views.len())
            .map(|p| model.views.pixels(p).map(|x| x.into_owned()))
            .collect::<Result<_>>()?;
        let keys: Vec<Vec<u32>> = set.samples.iter().map(|s| key(s, job.all)).collect();
        let mut settings = SolveSettings::pyramidal();
        settings.cg = job.settings.cg;
        let unbudgeted = LARGEST_FACE.min(job.req.max_texture.next_power_of_two() / 2).max(8);
        let cap = budget::face_cap(job.plan, job.req.codec);
        let largest = cap.map_or(unbudgeted, |c| c.face.min(unbudgeted));
        let cap_note = cap.and_then(|c| c.note(unbudgeted)).unwrap_or_default();
        // The report says so where a shell's face is at the cap the budget set.
        let at_cap = TextureLayout::cube(largest).texel_count();
        let with_note = |mut m: ObjectModel| {
            if m.layers.iter().any(|l| l.shell.is_some() && l.form.stored_texels(&[]) == at_cap) {
                m.why.push_str(&cap_note);
            }
            m
        };
        let lookups = job.req.shell_lookups;
        match job.req.representation {
            super::RepresentationMode::PemInfinity => {
                return single_shell(
                    model,
                    job,
                    o,
                    f0,
                    &pixels,
                    &keys,
                    &settings,
                    largest,
                    fitted.local.origin,
                )
                .map(with_note)
            }
            super::RepresentationMode::StaticEnv => {
                return traced::static_env(
                    model,
                    job,
                    o,
                    f0,
                    &pixels,
                    &keys,
                    largest,
                    fitted.local.origin,
                )
                .map(with_note)
            }
            _ => {}
        }
        let local_n = face_resolution(set, o, &job.meshes, &fitted.local, largest)?;
        let local_layout = TextureLayout::cube(local_n);
        let has_local = pixels
            .iter()
            .enumerate()
            .map(|(p, px)| local_alpha(set, p, o, px))
            .collect::<Result<Vec<f32>>>()?
            .iter()
            .any(|&a| a > 1e-3);
        let distant = distant_trial(job, o, &fitted, f0, (&pixels, &keys), &settings, largest)?;
        let (shell, n) = (distant.shell, distant.n);
        let mut shells = Vec::new();
        if has_local {
            shells.push((fitted.local.clone(), local_layout, Target::Local));
        }
        shells.push((shell, TextureLayout::cube(n), Target::Distant));
        // The convex-hull split (thesis 5.7): triangles on the hull never see the object, so
        // they draw the distant shell alone; the file stores them first.
        let hull = if has_local { hull_split(job, o)? } else { None };
        let local_drawn: Option<Vec<bool>> =
            hull.as_ref().map(|h| h.iter().map(|&on| !on).collect());
        let geometry: Vec<(Shell, TextureLayout, Option<&[bool]>)> = shells
            .iter()
            .map(|s| {
                (s.0.clone(), s.1, if s.2 == Target::Local { local_drawn.as_deref() } else { None })
            })
            .collect();
        let all: Vec<usize> = (0..set.frames.len()).collect();
        let views = shell_views(set, o, &job.meshes, &geometry, lookups, f0, (&pixels, &all))?;
        let shared: Vec<Vec<u32>> = set.samples.iter().map(|s| key(s, job.non_view)).collect();
        let mut solved = Vec::new();
        for (s, (shell, layout, target)) in shells.iter().enumerate() {
            solved.push(if shared_map(job, shell) {
                solve_shell_shared(&views, s, *layout, &shared, &settings, &job.solver)?
            } else {
                solve_shell(&views, s, *layout, *target, &keys, &settings, &job.solver)?
            });
        }
        let hull_text = match &hull {
            Some(h) => {
                model.hull_triangles = hull_first(&mut model.mesh.indices, h);
                format!(
                    ", {} of {} triangles on the convex hull draw the distant shell only",
                    model.hull_triangles,
                    h.len()
                )
            }
            None if has_local => {
                ", no convex-hull split (a part of a reflector of several objects)".to_string()
            }
            None => String::new(),
        };
        let local_text = if has_local {
            format!(", local ellipsoid {local_n}²{hull_text}")
        } else {
            String::new()
        };
        let why = format!("{}{local_text}{}", distant.why, lookups_text(lookups));
        let chosen = Chosen { shells, views, solved, why };
        push_shell_layers(&mut model, job, chosen.shells.iter().zip(chosen.solved));
        model.shells = Some(Box::new(ReflectionTerms(chosen.views)));
        model.representation = "layered environment maps".to_string();
        model.why = format!("reflective: {}, Fresnel from F0 {:?}", chosen.why, f0);
        Ok(with_note(model))
    }
}

/// Whether `shell` is solved as one map over the views: a depth shell, unless
/// `--distant-shell depth-per-sample` asks for one per sample.
fn shared_map(job: &Job<'_>, shell: &Shell) -> bool {
    is_depth(shell) && job.req.distant_shell.depth_map_shared()
}

/// The distant shell chosen for an object, its face size, and why.
struct DistantChoice {
    shell: Shell,
    n: u32,
    why: String,
}

/// The distant shell (thesis 5.4): a box and a sphere solved at a few points spread over the
/// set (`pixels` and `keys` per point), the one nearer the traced distant layer there kept;
/// then, where the scene has a depth shell to offer, the kept one and the depth shell each
/// judged between the samples ([`between::between_error`]) and the depth shell taken where
/// its error there is lower. `--distant-shell box|sphere|depth` takes that shell instead (a
/// depth shell where the scene has one to offer); `fitted` stops before the depth shell.
fn distant_trial(
    job: &Job<'_>,
    o: usize,
    fitted: &FittedShells,
    f0: [f32; 3],
    (pixels, keys): (&[Vec<u32>], &[Vec<u32>]),
    settings: &SolveSettings,
    largest: u32,
) -> Result<DistantChoice> {
    let set = job.set;
    let asked = match job.req.distant_shell {
        DistantShell::Auto | DistantShell::Fitted => None,
        DistantShell::Box => Some(("box", &fitted.distant_box)),
        DistantShell::Sphere => Some(("sphere", &fitted.distant_sphere)),
        DistantShell::Depth => fitted.distant_depth.as_ref().map(|d| ("depth", d)),
        DistantShell::DepthPerSample => {
            fitted.distant_depth.as_ref().map(|d| ("depth-per-sample", d))
        }
    };
    if let Some((label, shell)) = asked {
        let n = face_resolution(set, o, &job.meshes, shell, largest)?;
        let why = format!("distant {label} {n}² (--distant-shell {label})");
        return Ok(DistantChoice { shell: shell.clone(), n, why });
    }
    let probe: Vec<usize> = probe_points(set.frames.len());
    let probe_pixels: Vec<Vec<u32>> = probe.iter().map(|&p| pixels[p].clone()).collect();
    let probe_keys: Vec<Vec<u32>> = probe.iter().map(|&p| keys[p].clone()).collect();
    let mut trial: Vec<(f64, &str, &Shell, u32)> = Vec::new();
    for (label, shell) in [("box", &fitted.distant_box), ("sphere", &fitted.distant_sphere)] {
        let n = face_resolution(set, o, &job.meshes, shell, largest)?;
        let layout = TextureLayout::cube(n);
        let views = shell_views(
            set,
            o,
            &job.meshes,
            &[(shell.clone(), layout, None)],
            job.req.shell_lookups,
            f0,
            (&probe_pixels, &probe),
        )?;
        let solved =
            solve_shell(&views, 0, layout, Target::Distant, &probe_keys, settings, &job.solver)?;
        trial.push((solved.residual_rms, label, shell, n));
    }
    trial.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (residual, label, shell, n) = trial[0];
    let mut choice = DistantChoice {
        shell: shell.clone(),
        n,
        why: format!(
            "distant {label} {n}² (traced distant layer residual {residual:.4}, {} {:.4})",
            trial[1].1, trial[1].0
        ),
    };
    let classes: Vec<Vec<u32>> = set.samples.iter().map(|s| key(s, job.non_view)).collect();
    let depth = fitted.distant_depth.as_ref();
    let (Some(depth), Some(points)) = (depth, held_out_points(&classes)) else {
        return Ok(choice);
    };
    let depth_n = face_resolution(set, o, &job.meshes, depth, largest)?;
    let judge =
        |shell: &Shell, n: u32| between_error(job, o, (shell, n), f0, (pixels, points), settings);
    if let (Some(kept), Some(marched)) = (judge(shell, n)?, judge(depth, depth_n)?) {
        let [a, m, b] = points;
        let at = format!("at point {m} solved from {a} and {b}");
        if marched < kept {
            choice = DistantChoice {
                shell: depth.clone(),
                n: depth_n,
                why: format!("distant depth {depth_n}² (error between the samples {marched:.4} {at}, {label} {kept:.4})"),
            };
        } else {
            choice.why.push_str(&format!("; a depth shell's error between the samples {marched:.4} {at}, {label}'s {kept:.4}"));
        }
    }
    Ok(choice)
}

/// Each solved shell as a layer of `model`, in order (the local shell first where there is
/// one), looked up in the reflection term.
fn push_shell_layers<'s>(
    model: &mut ObjectModel,
    job: &Job<'_>,
    shells: impl Iterator<Item = (&'s (Shell, TextureLayout, Target), SolvedShell)>,
) {
    for (s, ((shell, layout, target), solved)) in shells.enumerate() {
        let kind = if *target == Target::Local {
            pis_format::LayerKind::EnvLocal
        } else {
            pis_format::LayerKind::EnvDistant
        };
        let form = Box::new(ShellForm {
            shell: shell.clone(),
            layout: *layout,
            lookups: job.req.shell_lookups,
            channels: target.channels() as u8,
            order: s as u8,
            term: pis_format::Term::Reflection,
        });
        // A depth shell's map is one over the views (`solve_shell_shared`).
        let mask = if shared_map(job, shell) { job.non_view } else { job.all };
        model.layers.push(InferredLayer::shell(
            kind,
            (&job.plan.space, mask),
            &model.stagger,
            solved.textures,
            solved.iterations,
            form,
            s,
        ));
    }
}

/// The single-shell baseline (thesis 5.10): one sphere-at-infinity map per sample against
/// all the traced incident light.
#[allow(clippy::too_many_arguments)]
fn single_shell(
    mut model: ObjectModel,
    job: &Job<'_>,
    o: usize,
    f0: [f32; 3],
    pixels: &[Vec<u32>],
    keys: &[Vec<u32>],
    settings: &SolveSettings,
    largest: u32,
    origin: glam::DVec3,
) -> Result<ObjectModel> {
    let set = job.set;
    let shell = fit::sphere_at_infinity(origin);
    let lookups = job.req.shell_lookups;
    let n = face_resolution(set, o, &job.meshes, &shell, largest)?;
    let layout = TextureLayout::cube(n);
    let all: Vec<usize> = (0..set.frames.len()).collect();
    let views = shell_views(
        set,
        o,
        &job.meshes,
        &[(shell.clone(), layout, None)],
        lookups,
        f0,
        (pixels, &all),
    )?;
    let solved = solve_shell(&views, 0, layout, Target::Incident, keys, settings, &job.solver)?;
    let form = Box::new(ShellForm {
        shell,
        layout,
        lookups,
        channels: 3,
        order: 0,
        term: pis_format::Term::Reflection,
    });
    model.layers.push(InferredLayer::shell(
        pis_format::LayerKind::EnvDistant,
        (&job.plan.space, job.all),
        &model.stagger,
        solved.textures,
        solved.iterations,
        form,
        0,
    ));
    model.shells = Some(Box::new(ReflectionTerms(views)));
    model.representation = "environment map at infinity".to_string();
    model.why = format!("--representation pem-infinity: one sphere-at-infinity map {n}² per sample (traced incident light residual {:.4}){}, Fresnel from F0 {f0:?}", solved.residual_rms, lookups_text(lookups));
    Ok(model)
}

/// Per triangle of object `o`'s mesh, whether it lies on the mesh's convex hull; `None` when
/// the object is a part of a reflector of several objects, whose other parts a hull
/// triangle may see.
fn hull_split(job: &Job<'_>, o: usize) -> Result<Option<Vec<bool>>> {
    let scene = &job.set.scene;
    let reflector = scene.reflector_of(o);
    if (0..scene.objects.len()).any(|k| k != o && scene.reflector_of(k) == reflector) {
        return Ok(None);
    }
    let mesh = &job.meshes[o];
    let positions: Vec<glam::Vec3> = mesh.positions.iter().map(|&p| glam::Vec3::from(p)).collect();
    Ok(Some(crate::pipeline::shell_fit::convex_hull_triangles(&positions, &mesh.indices)?))
}

/// Reorders the triangles of `indices` so those with `hull` set come first, each group in
/// its order; returns how many are on the hull.
fn hull_first(indices: &mut Vec<u32>, hull: &[bool]) -> u32 {
    let tris: Vec<[u32; 3]> = indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
    let (on, off): (Vec<_>, Vec<_>) = tris.iter().zip(hull).partition(|(_, &h)| h);
    *indices = on.iter().chain(&off).flat_map(|(t, _)| t.iter().copied()).collect();
    on.len() as u32
}

/// Whether the set has the tracer's local and distant layers of object `o`, which layered
/// environment maps are solved against.
pub fn layered(set: &super::input::LoadedSet, o: usize) -> bool {
    set.images.object(0, o).is_ok_and(|i| {
        i.object_layer(&set.channels[o], TraceLayer::Local).is_some()
            && i.object_layer(&set.channels[o], TraceLayer::Distant).is_some()
    })
}

/// At most three points spread over `n`: first, middle, last.
fn probe_points(n: usize) -> Vec<usize> {
    let mut p = vec![0, n / 2, n.saturating_sub(1)];
    p.dedup();
    p
}

/// The largest traced local alpha of object `o` over `pixels` at point `p`.
fn local_alpha(set: &super::input::LoadedSet, p: usize, o: usize, pixels: &[u32]) -> Result<f32> {
    Ok(set
        .images
        .object(p, o)?
        .object_layer(&set.channels[o], TraceLayer::Local)
        .and_then(|l| l.channel("A"))
        .map_or(0.0, |a| pixels.iter().map(|&px| a[px as usize]).fold(0.0, f32::max)))
}

#[cfg(test)]
mod tests {
    use super::hull_first;

    #[test]
    fn hull_triangles_move_first_in_their_order() {
        let mut indices = vec![0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11];
        let hull = [false, true, false, true];
        assert_eq!(hull_first(&mut indices, &hull), 2);
        assert_eq!(indices, [3, 4, 5, 9, 10, 11, 0, 1, 2, 6, 7, 8]);
    }
}
