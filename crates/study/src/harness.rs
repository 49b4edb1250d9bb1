//! The comparison harness: every sphere method and the reference ray tracer on the same scene,
//! camera and shading, measured for speed and accuracy.
//!
//! For a [`NamedScene`] the harness
//! 1. builds the reference ([`texmap_reftrace`]) from the same spheres and materials and traces it
//!    at one sample per pixel (and, optionally, `n x n` supersampled for an anti-aliased colour
//!    reference) with the same [`Lighting`] and background;
//! 2. draws the scene with each [`Method`] through one [`Renderer`] that is reused across runs,
//!    as the papers' per-scene tables intend (Seed 002 lights its colour images once per scene,
//!    Seed 004 builds its template pyramid once), after `warmup` untimed runs, and reports the
//!    median of `runs` timed runs;
//! 3. compares each frame with the reference through [`texmap_core::metrics`]: PSNR and SSIM of
//!    the 8-bit sRGB colour, depth error over the pixels both cover, silhouette mismatch.
//!
//! Bonds are drawn and traced only in scenes that ask for it ([`NamedScene::draw_bonds`], the
//! ball-and-stick molecule): every method then draws them with the shared exact cylinder pass and
//! the reference traces each bond as two capped half-cylinders in the two atoms' materials
//! ([`reference_scene_with_bonds`]). In the space-filling scenes they lie inside the atoms and
//! are neither drawn nor traced.
//!
//! Everything returns data; files are written only by the explicit `write_*` functions, which
//! take a directory.

use texmap_core::camera::Camera;
use texmap_core::color::srgb8_to_linear_rgb;
use texmap_core::frame::Frame;
use texmap_core::shade::Lighting;
use texmap_impostor::{Method, Options, Renderer, SphereScene};
use texmap_reftrace::{RenderOptions, SceneBuilder, SurfaceMaterial};

use crate::error::StudyError;
use crate::record::time_ms;
pub use crate::record::{
    Metrics, Record, compare, error_image, mean_covered_color, record, records_to_csv,
    records_to_json, write_results,
};
use crate::scenes::NamedScene;

/// The reference ray tracer's scene for a sphere set: the same spheres with material id = kind.
/// Invalid spheres (non-finite, non-positive radius) are skipped by the builder, as the methods
/// skip them; spheres of an unknown kind are left out here for the same reason.
pub fn reference_scene(spheres: &SphereScene) -> texmap_reftrace::Scene {
    reference_scene_with_bonds(spheres, false)
}

/// [`reference_scene`] plus, when `bonds` is set, every drawable bond of `spheres` as two capped
/// cylinders of its radius (`bond_radius_of`), from each atom's centre to the bond's midpoint in that
/// atom's material (half-bond colouring, as the methods draw it). Bonds the methods skip (an
/// index out of range, an invalid atom, coincident centres, a bad radius) are left out.
pub fn reference_scene_with_bonds(spheres: &SphereScene, bonds: bool) -> texmap_reftrace::Scene {
    reference_builder(spheres, bonds).build()
}

/// [`reference_scene_with_bonds`] plus meshes (molecular surfaces, cartoons): each material's
/// triangles of each mesh as one mesh shaded by its vertex normals, material id = kind, as
/// `md_scene::surface::draw_mesh` draws them; triangles of an unknown kind are left out.
pub fn reference_scene_with_meshes(
    spheres: &SphereScene,
    bonds: bool,
    meshes: &[&texmap_md_scene::surface::MolMesh],
) -> texmap_reftrace::Scene {
    let mut b = reference_builder(spheres, bonds);
    for mesh in meshes {
        let groups = mesh.by_kind(spheres.materials.len());
        for (kind, group) in groups.iter().enumerate().take(spheres.materials.len()) {
            if group.is_empty() {
                continue;
            }
            b.add_mesh_shaded(
                &mesh.positions,
                group.as_flattened(),
                None,
                Some(&mesh.normals),
                texmap_reftrace::MeshShading::VertexNormals,
                kind as u32,
            )
            .expect("a mesh's indices and normals match its vertices");
        }
    }
    b.build()
}

/// The reference builder of [`reference_scene_with_bonds`].
fn reference_builder(spheres: &SphereScene, bonds: bool) -> SceneBuilder {
    let mut b = SceneBuilder::with_sphere_capacity(spheres.len());
    for i in 0..spheres.len() {
        if (spheres.kinds[i] as usize) < spheres.materials.len() {
            b.add_sphere(
                spheres.centers[i],
                spheres.radii[i],
                spheres.kinds[i] as u32,
            );
        }
    }
    if bonds {
        for (k, &[i, j]) in spheres.bonds.iter().enumerate() {
            let (i, j) = (i as usize, j as usize);
            let r = spheres.bond_radius_of(k);
            if r.is_finite()
                && r > 0.0
                && i < spheres.len()
                && j < spheres.len()
                && spheres.is_valid(i)
                && spheres.is_valid(j)
                && spheres.centers[i] != spheres.centers[j]
            {
                let (pa, pb) = (spheres.centers[i], spheres.centers[j]);
                let mid = (pa + pb) * 0.5;
                b.add_cylinder(pa, mid, r, spheres.kinds[i] as u32);
                b.add_cylinder(mid, pb, r, spheres.kinds[j] as u32);
            }
        }
    }
    b
}

/// The reference materials: every kind's shading material, opaque.
pub fn reference_materials(spheres: &SphereScene) -> Vec<SurfaceMaterial> {
    spheres
        .materials
        .iter()
        .map(|m| SurfaceMaterial::opaque(*m))
        .collect()
}

/// Trace the reference: `samples_per_axis²` stratified samples per pixel, the same lighting and
/// the background of `background` (sRGB RGBA, as in [`Options::background`]).
pub fn render_reference(
    scene: &texmap_reftrace::Scene,
    materials: &[SurfaceMaterial],
    camera: &Camera,
    lighting: Lighting,
    background: [u8; 4],
    samples_per_axis: u32,
) -> Result<Frame, StudyError> {
    let mut o = RenderOptions::new(lighting, materials);
    o.samples_per_axis = samples_per_axis;
    o.background = srgb8_to_linear_rgb(background);
    Ok(scene.render(camera, &o)?)
}

/// How the harness runs.
#[derive(Clone, Debug, PartialEq)]
pub struct HarnessOptions {
    pub methods: Vec<Method>,
    /// Untimed runs before timing (at least the first run builds the per-scene tables).
    pub warmup: usize,
    /// Timed runs; the median is reported (at least 1).
    pub runs: usize,
    /// Also trace an `n x n` supersampled reference and report every method against it too.
    pub supersample: Option<u32>,
    /// Time the reference too (a `reftrace` record).
    pub time_reference: bool,
}

impl Default for HarnessOptions {
    /// All four methods, 1 warm-up and 5 timed runs, no supersampled reference, reference timed.
    fn default() -> HarnessOptions {
        HarnessOptions {
            methods: Method::ALL.to_vec(),
            warmup: 1,
            runs: 5,
            supersample: None,
            time_reference: true,
        }
    }
}

/// The options every method is drawn with in the study: the method's defaults, the scene's
/// lighting, no bonds (the harness turns them on for scenes with [`NamedScene::draw_bonds`]).
pub fn study_options(method: Method, lighting: Lighting) -> Options {
    let mut o = Options::new(method, lighting);
    o.draw_bonds = false;
    o
}

/// One method's outcome on a scene.
#[derive(Clone, Debug)]
pub struct MethodRun {
    pub method: Method,
    pub frame: Frame,
    /// Against the 1-spp reference.
    pub metrics: Metrics,
    /// Against the supersampled reference, when asked for.
    pub metrics_ss: Option<Metrics>,
    pub ms_per_frame: f64,
}

/// Everything the harness found on one scene.
#[derive(Clone, Debug)]
pub struct SceneReport {
    pub scene: String,
    pub reference: Frame,
    pub reference_ss: Option<Frame>,
    /// Median ms per reference frame at 1 spp (BVH built once, outside the timing).
    pub reference_ms: Option<f64>,
    pub runs: Vec<MethodRun>,
    pub records: Vec<Record>,
}

/// Run every asked-for method and the reference on `scene`.
pub fn run_scene(scene: &NamedScene, opts: &HarnessOptions) -> Result<SceneReport, StudyError> {
    run_scene_with_progress(scene, opts, &mut |_| {})
}

/// [`run_scene`], calling `step` with the name of each stage (`"reference"`, then each
/// method's name) before it starts: `1 + opts.methods.len()` calls.
pub fn run_scene_with_progress(
    scene: &NamedScene,
    opts: &HarnessOptions,
    step: &mut dyn FnMut(&str),
) -> Result<SceneReport, StudyError> {
    if let Some(n) = opts.supersample
        && !(1..=texmap_reftrace::MAX_SAMPLES_PER_AXIS).contains(&n)
    {
        return Err(StudyError::BadOption {
            what: "supersample",
            value: n.to_string(),
        });
    }
    let background = study_options(Method::Raycast, scene.lighting).background;
    let rscene = reference_scene_with_bonds(&scene.spheres, scene.draw_bonds);
    let mats = reference_materials(&scene.spheres);
    let trace = |spp| {
        render_reference(
            &rscene,
            &mats,
            &scene.camera,
            scene.lighting,
            background,
            spp,
        )
    };
    step("reference");
    let (reference_ms, reference) = if opts.time_reference {
        let (ms, f) = time_ms(0, opts.runs.min(3), || trace(1));
        (Some(ms), f?)
    } else {
        (None, trace(1)?)
    };
    let reference_ss = opts.supersample.map(trace).transpose()?;
    let ss_name = opts.supersample.map(|n| format!("reftrace-{n}x{n}"));

    let name = scene.name();
    let mut records = Vec::new();
    if let Some(ms) = reference_ms {
        let m = compare(&reference, &reference)?;
        records.push(record(
            name,
            "reftrace",
            "reftrace-1spp",
            &reference,
            ms,
            &m,
        ));
    }
    let mut runs = Vec::new();
    for &method in &opts.methods {
        step(method.name());
        let mut o = study_options(method, scene.lighting);
        o.draw_bonds = scene.draw_bonds;
        let mut renderer = Renderer::new();
        let (ms, out) = time_ms(opts.warmup, opts.runs, || {
            renderer.render(&scene.spheres, &scene.camera, &o)
        });
        let frame = out.frame;
        let m = compare(&frame, &reference)?;
        records.push(record(name, method.name(), "reftrace-1spp", &frame, ms, &m));
        let metrics_ss = match (&reference_ss, &ss_name) {
            (Some(r), Some(n)) => {
                let mss = compare(&frame, r)?;
                records.push(record(name, method.name(), n, &frame, ms, &mss));
                Some(mss)
            }
            _ => None,
        };
        runs.push(MethodRun {
            method,
            frame,
            metrics: m,
            metrics_ss,
            ms_per_frame: ms,
        });
    }
    Ok(SceneReport {
        scene: name.to_string(),
        reference,
        reference_ss,
        reference_ms,
        runs,
        records,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenes::{SceneId, build_sized};

    #[test]
    fn ball_and_stick_scene_draws_and_traces_its_bonds() {
        let scene = build_sized(SceneId::MoleculeBallStick, 160, 160).unwrap();
        let opts = HarnessOptions {
            methods: vec![Method::Raycast, Method::Lut],
            warmup: 0,
            runs: 1,
            supersample: None,
            time_reference: false,
        };
        let rep = run_scene(&scene, &opts).unwrap();
        // Without the bonds in the reference the sticks would be silhouette errors; with them the
        // exact method agrees with the reference as on the space-filling scenes.
        let bare = reference_scene_with_bonds(&scene.spheres, false);
        let mats = reference_materials(&scene.spheres);
        let bg = study_options(Method::Raycast, scene.lighting).background;
        let no_bonds =
            render_reference(&bare, &mats, &scene.camera, scene.lighting, bg, 1).unwrap();
        let raycast = &rep.runs[0];
        let m_bare = compare(&raycast.frame, &no_bonds).unwrap();
        assert!(
            m_bare.silhouette_mismatched > 60,
            "the bonds should cover many pixels: {} mismatched against the bond-less reference",
            m_bare.silhouette_mismatched
        );
        assert!(
            raycast.metrics.psnr_db >= 45.0 && raycast.metrics.silhouette_px <= 0.05,
            "raycast vs reference with bonds: PSNR {} dB (expected ≥ 45), silhouette {} px \
             (expected ≤ 0.05)",
            raycast.metrics.psnr_db,
            raycast.metrics.silhouette_px
        );
    }

    #[test]
    fn records_round_trip_through_json_including_infinite_psnr() {
        let r = Record {
            scene: "s1".into(),
            method: "raycast".into(),
            reference: "reftrace-1spp".into(),
            width: 5,
            height: 4,
            ms_per_frame: 1.25,
            psnr_db: f64::INFINITY,
            ssim: 1.0,
            depth_err_mean: 0.0,
            depth_err_max: 0.0,
            silhouette_px: 0.0,
            silhouette_mismatched: 0,
        };
        let json = records_to_json(std::slice::from_ref(&r)).unwrap();
        assert!(json.contains("\"psnr_db\": null"), "{json}");
        let back: Vec<Record> = serde_json::from_str(&json).unwrap();
        assert_eq!(back, vec![r.clone()]);
        let csv = records_to_csv(&[r]);
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines.len(), 2);
        // Same number of columns in header and row.
        assert_eq!(lines[0].split(',').count(), lines[1].split(',').count());
        assert!(lines[1].contains(",inf,"), "{}", lines[1]);
    }

    #[test]
    fn error_image_marks_coverage_mismatch_and_amplifies_differences() {
        let mut a = Frame::new(3, 1, [0, 0, 0, 255]);
        let mut r = Frame::new(3, 1, [0, 0, 0, 255]);
        a.depth[0] = 1.0; // only the frame covers pixel 0
        r.depth[1] = 1.0; // only the reference covers pixel 1
        a.depth[2] = 1.0;
        r.depth[2] = 1.0;
        a.color[2] = [100, 100, 100, 255];
        r.color[2] = [90, 100, 140, 255];
        let e = error_image(&a, &r, 4.0).unwrap();
        assert_eq!(e.color[0], [255, 0, 255, 255]);
        assert_eq!(e.color[1], [0, 255, 0, 255]);
        assert_eq!(e.color[2], [40, 0, 160, 255]);
        assert!(error_image(&a, &Frame::new(2, 1, [0; 4]), 1.0).is_err());
    }

    #[test]
    fn reference_agrees_with_itself_and_harness_reports_every_method() {
        // A small S1 view keeps the test fast; the figures themselves are checked in sweeps.
        let scene = build_sized(SceneId::S1, 96, 96).unwrap();
        let opts = HarnessOptions {
            warmup: 0,
            runs: 1,
            supersample: Some(2),
            ..HarnessOptions::default()
        };
        let rep = run_scene(&scene, &opts).unwrap();
        // reftrace + 4 methods x (1 spp + 2x2).
        assert_eq!(rep.records.len(), 1 + 4 * 2);
        let own = &rep.records[0];
        assert_eq!(own.method, "reftrace");
        assert!(own.psnr_db.is_infinite() && own.silhouette_mismatched == 0);
        assert!(rep.reference.coverage_count() > 96 * 96 / 4);
        for r in &rep.records[1..] {
            assert_eq!((r.width, r.height), (96, 96));
            assert!(r.ms_per_frame.is_finite() && r.ms_per_frame >= 0.0);
            assert!(r.ssim.is_finite() && r.psnr_db > 0.0, "{r:?}");
        }
    }
}
