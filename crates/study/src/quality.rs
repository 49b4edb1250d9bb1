//! The quality axis of the study: what anti-aliasing, ambient occlusion and shadows from
//! `texmap-quality` cost in time and how close each setting comes to a converged reference.
//!
//! Every setting in [`quality_settings`] is timed (median of `runs` frames, a
//! [`QualityRenderer`] reused) and compared with a reference traced by `texmap-reftrace` with the
//! **same** effects: `ref_samples_per_axis²` stratified samples per pixel and, where the setting
//! has ambient occlusion, `ref_ao_samples_per_axis²` AO rays per sample at the same AO distance,
//! and shadows from the same key light. So a setting without AO is measured against the
//! supersampled plain image and a setting with AO and shadows against the supersampled AO and
//! shadow image; the error left is aliasing plus AO noise. Outlines and soft shadows are not
//! among the settings measured here ([`reference_with`] traces them for `--method reference`).
//!
//! The results are [`Record`]s (method = the setting's name, reference = e.g.
//! `reftrace-8x8-ao256-shadows`), written as `quality.json` / `quality.csv`, and the
//! speed-against-accuracy chart of them as `quality.svg` ([`write_quality`]).

use std::path::{Path, PathBuf};

use texmap_core::camera::Camera;
use texmap_core::color::srgb8_to_linear_rgb;
use texmap_core::frame::Frame;
use texmap_core::shade::Lighting;
use texmap_impostor::SphereScene;
use texmap_quality::{QualityOptions, QualityRenderer, ao_distance_for};
use texmap_reftrace::{AmbientOcclusion, RenderOptions};

use crate::chart::{self, Target};
use crate::error::{StudyError, write_file};
use crate::harness::{
    reference_materials, reference_scene_with_bonds, reference_scene_with_meshes,
};
use crate::record::{Record, compare, record, records_to_csv, records_to_json, time_ms};
use crate::scenes::NamedScene;
use texmap_md_scene::surface::MolMesh;

/// The least ambient-occlusion distance (Å) of a scene with meshes, when the options give
/// none: about the gap between packed helices, so that a cartoon's grooves darken.
pub const MESH_AO_DISTANCE: f32 = 6.0;

/// A named quality setting.
#[derive(Clone, Debug, PartialEq)]
pub struct QualitySetting {
    pub name: String,
    pub options: QualityOptions,
}

/// The reference ray tracer's image of `spheres` with the effects `q` asks for, so that a
/// quality setting of `texmap render --method reference` has its converged counterpart:
/// `⌈√aa⌉²` samples per pixel, ambient occlusion with at least `ao_samples` rays per pixel
/// (`m²` per sample, the same distance: `q.ao_distance` or [`ao_distance_for`]), hard shadows,
/// soft shadows from the same disc with at least `samples` rays per pixel (`m²` per sample),
/// the same depth cueing and the same outline rule applied to every sample. A transparent
/// background is not drawn by the reference (the background colour is used, black for a
/// transparent one).
///
/// `meshes` (cartoons, surfaces, polyhedra, isosurfaces: opaque) are traced with the spheres,
/// casting and receiving the same occlusion and shadows; without an AO distance in `q`, a
/// scene with meshes takes at least [`MESH_AO_DISTANCE`] (a cartoon's spheres, if any, are
/// ligands: their radii say nothing of the distance between helices).
pub fn reference_with(
    spheres: &SphereScene,
    draw_bonds: bool,
    meshes: &[&MolMesh],
    camera: &Camera,
    lighting: Lighting,
    q: &QualityOptions,
) -> Result<Frame, StudyError> {
    q.validate().map_err(|e| StudyError::BadOption {
        what: "quality options",
        value: e.to_string(),
    })?;
    let meshes: Vec<&MolMesh> = meshes
        .iter()
        .copied()
        .filter(|m| !m.triangles.is_empty())
        .collect();
    let rscene = if meshes.is_empty() {
        reference_scene_with_bonds(spheres, draw_bonds)
    } else {
        reference_scene_with_meshes(spheres, draw_bonds, &meshes)
    };
    let mats = reference_materials(spheres);
    let n = (q.aa as f64).sqrt().ceil().max(1.0) as u32;
    let mut o = RenderOptions::new(lighting, &mats);
    o.samples_per_axis = n.min(texmap_reftrace::MAX_SAMPLES_PER_AXIS);
    let bg = match q.background {
        texmap_quality::Background::Color(c) => [c[0], c[1], c[2], 255],
        texmap_quality::Background::Transparent => [0, 0, 0, 255],
    };
    o.background = srgb8_to_linear_rgb(bg);
    if q.ao_samples > 0 {
        let per_sample = (q.ao_samples as f64 / (n * n) as f64)
            .sqrt()
            .ceil()
            .max(1.0) as u32;
        o.ambient_occlusion = Some(AmbientOcclusion {
            samples_per_axis: per_sample.min(texmap_reftrace::MAX_AO_SAMPLES_PER_AXIS),
            distance: q.ao_distance.unwrap_or_else(|| {
                let d = ao_distance_for(spheres);
                if meshes.is_empty() {
                    d
                } else {
                    d.max(MESH_AO_DISTANCE)
                }
            }),
        });
    }
    o.shadows = q.shadows;
    o.soft_shadows = q.soft_shadows.map(|ss| {
        let per_sample = (ss.samples as f64 / (n * n) as f64).sqrt().ceil().max(1.0) as u32;
        texmap_reftrace::DiscLight {
            samples_per_axis: per_sample.min(texmap_reftrace::MAX_SHADOW_SAMPLES_PER_AXIS),
            size_deg: ss.light_size_deg,
        }
    });
    o.outline = q.outline.map(|ol| texmap_reftrace::Outline {
        width_px: ol.width_px,
        color: srgb8_to_linear_rgb([ol.color[0], ol.color[1], ol.color[2], 255]),
    });
    o.fog = q.fog.map(|f| texmap_reftrace::DepthCue {
        start: f.start,
        end: f.end,
        color: srgb8_to_linear_rgb([f.color[0], f.color[1], f.color[2], 255]),
        strength: f.strength,
    });
    Ok(rscene.render(camera, &o)?)
}

/// The settings of the study: the plain ray-cast image, edge anti-aliasing at 4 and 16
/// samples, and AO + shadows at 8 and 32 rays with 1, 4 and 16 edge samples (the issue's
/// "4x AA + AO 8 + shadows" is `aa4-ao8-shadows`, the `good` preset).
pub fn quality_settings() -> Vec<QualitySetting> {
    let mk = |aa: u32, ao: u32, shadows: bool| {
        let mut name = format!("aa{aa}");
        if ao > 0 {
            name.push_str(&format!("-ao{ao}"));
        }
        if shadows {
            name.push_str("-shadows");
        }
        QualitySetting {
            name,
            options: QualityOptions {
                aa,
                ao_samples: ao,
                shadows,
                ..QualityOptions::draft()
            },
        }
    };
    vec![
        mk(1, 0, false),
        mk(4, 0, false),
        mk(16, 0, false),
        mk(1, 8, true),
        mk(4, 8, true),
        mk(4, 32, true),
        mk(16, 32, true),
    ]
}

/// How the quality study runs.
#[derive(Clone, Debug, PartialEq)]
pub struct QualityStudyOptions {
    /// Reference samples per pixel axis (1..=16).
    pub ref_samples_per_axis: u32,
    /// Reference AO rays per sample axis (1..=64); per pixel the reference traces
    /// `(ref_samples_per_axis · ref_ao_samples_per_axis)²` AO rays.
    pub ref_ao_samples_per_axis: u32,
    pub warmup: usize,
    pub runs: usize,
}

impl Default for QualityStudyOptions {
    /// An 8x8 reference with 2x2 AO rays per sample: 256 AO rays per pixel.
    fn default() -> QualityStudyOptions {
        QualityStudyOptions {
            ref_samples_per_axis: 8,
            ref_ao_samples_per_axis: 2,
            warmup: 1,
            runs: 5,
        }
    }
}

/// One setting's record and frame.
#[derive(Clone, Debug)]
pub struct QualityRun {
    pub record: Record,
    pub frame: Frame,
}

/// A scene's quality study: the references (plain, and with AO + shadows) and every setting.
#[derive(Clone, Debug)]
pub struct QualityReport {
    pub runs: Vec<QualityRun>,
    /// `(name, frame)` of each reference traced.
    pub references: Vec<(String, Frame)>,
}

/// Run every setting of [`quality_settings`] on `scene` (module docs).
pub fn run_quality(
    scene: &NamedScene,
    opts: &QualityStudyOptions,
) -> Result<QualityReport, StudyError> {
    let settings = quality_settings();
    let spheres = &scene.spheres;
    let rscene = reference_scene_with_bonds(spheres, scene.draw_bonds);
    let mats = reference_materials(spheres);
    let ao_distance = ao_distance_for(spheres);
    let n = opts.ref_samples_per_axis;
    let m = opts.ref_ao_samples_per_axis;
    let mut references: Vec<(String, Frame)> = Vec::new();
    let mut runs = Vec::new();
    let mut renderer = QualityRenderer::new();
    for s in settings {
        let mut q = s.options;
        q.draw_bonds = scene.draw_bonds;
        q.ao_distance = Some(ao_distance);
        let with_ao = q.ao_samples > 0;
        let ref_name = if with_ao || q.shadows {
            format!(
                "reftrace-{n}x{n}{}{}",
                if with_ao {
                    format!("-ao{}", n * n * m * m)
                } else {
                    String::new()
                },
                if q.shadows { "-shadows" } else { "" }
            )
        } else {
            format!("reftrace-{n}x{n}")
        };
        if !references.iter().any(|(name, _)| *name == ref_name) {
            let mut o = RenderOptions::new(scene.lighting, &mats);
            o.samples_per_axis = n;
            o.background = srgb8_to_linear_rgb([0, 0, 0, 255]);
            o.ambient_occlusion = with_ao.then_some(AmbientOcclusion {
                samples_per_axis: m,
                distance: ao_distance,
            });
            o.shadows = q.shadows;
            references.push((ref_name.clone(), rscene.render(&scene.camera, &o)?));
        }
        let reference = &references
            .iter()
            .find(|(name, _)| *name == ref_name)
            .expect("traced above")
            .1;
        let mut err = None;
        let (ms, out) = time_ms(opts.warmup, opts.runs, || {
            match renderer.render(spheres, &scene.camera, &scene.lighting, &q) {
                Ok(r) => Some(r.frame),
                Err(e) => {
                    err = Some(e);
                    None
                }
            }
        });
        let frame = match (out, err) {
            (Some(f), None) => f,
            (_, e) => {
                return Err(StudyError::BadOption {
                    what: "quality options",
                    value: format!("{e:?}"),
                });
            }
        };
        let metrics = compare(&frame, reference)?;
        runs.push(QualityRun {
            record: record(scene.name(), &s.name, &ref_name, &frame, ms, &metrics),
            frame,
        });
    }
    Ok(QualityReport { runs, references })
}

/// Write `quality.json`, `quality.csv` and the chart `quality.svg` (speed against PSNR) into
/// `dir` (which must exist); returns the paths written.
pub fn write_quality(dir: &Path, records: &[Record]) -> Result<Vec<PathBuf>, StudyError> {
    let json = dir.join("quality.json");
    write_file(json.clone(), records_to_json(records)?.as_bytes())?;
    let csv = dir.join("quality.csv");
    write_file(csv.clone(), records_to_csv(records).as_bytes())?;
    let mut svg = String::new();
    chart::speed_accuracy(records, Target::Svg(&mut svg))?;
    let svg_path = dir.join("quality.svg");
    write_file(svg_path.clone(), svg.as_bytes())?;
    Ok(vec![json, csv, svg_path])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenes::{SceneId, build_sized};

    #[test]
    fn quality_axis_on_a_small_s1() {
        let s = build_sized(SceneId::S1, 96, 96).unwrap();
        let opts = QualityStudyOptions {
            ref_samples_per_axis: 4,
            ref_ao_samples_per_axis: 2,
            warmup: 0,
            runs: 1,
        };
        let rep = run_quality(&s, &opts).unwrap();
        assert_eq!(rep.runs.len(), quality_settings().len());
        assert_eq!(rep.references.len(), 2);
        let psnr = |name: &str| {
            rep.runs
                .iter()
                .find(|r| r.record.method == name)
                .unwrap()
                .record
                .psnr_db
        };
        // Edge anti-aliasing closes most of the gap to the supersampled reference.
        assert!(
            psnr("aa16") > psnr("aa1") + 5.0,
            "{} vs {}",
            psnr("aa16"),
            psnr("aa1")
        );
        // More AO rays and more edge samples: closer to the converged AO + shadow reference.
        assert!(psnr("aa16-ao32-shadows") > psnr("aa1-ao8-shadows"));
        let dir = tempfile::tempdir().unwrap();
        let recs: Vec<Record> = rep.runs.iter().map(|r| r.record.clone()).collect();
        let written = write_quality(dir.path(), &recs).unwrap();
        assert_eq!(written.len(), 3);
        let csv = std::fs::read_to_string(&written[1]).unwrap();
        assert!(
            csv.contains("aa4-ao8-shadows,reftrace-4x4-ao64-shadows"),
            "{csv}"
        );
    }
}
