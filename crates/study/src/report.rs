//! The demo's report page: one self-contained `index.html` that a scientist can read without
//! knowing the code — what each method is, what each number means, what each sweep varies,
//! the colours of the elements and of the error images, and the charts.
//!
//! [`demo_index_html`] writes the page from the measured records; other capabilities
//! (terrain, environment mapping, quality) add [`Section`]s of their own.

use std::path::{Path, PathBuf};

use crate::elements::SEED004_SPECIES;
use crate::harness::SceneReport;

/// Error images amplify the per-channel difference from the reference by this factor.
pub const ERROR_GAIN: f32 = 8.0;

/// What the animation measured per method.
#[derive(Clone, Debug)]
pub struct AnimationSummary {
    pub method: &'static str,
    pub frames: usize,
    /// Mean wall time per frame of the animation (one run per frame, cold per-scene tables
    /// on the first frame, PNG writing excluded).
    pub ms_per_frame: f64,
}

/// A further part of the page: a heading and its HTML body (already escaped).
#[derive(Clone, Debug)]
pub struct Section {
    pub title: String,
    pub html: String,
}

fn rel(path: &Path, base: &Path) -> String {
    path.strip_prefix(base)
        .unwrap_or(path)
        .to_string_lossy()
        .replace('\\', "/")
}

/// Escapes text for HTML.
pub fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

const STYLE: &str = "body{font-family:sans-serif;margin:2em;max-width:1200px;line-height:1.4}\
table{border-collapse:collapse}td,th{border:1px solid #bbb;padding:4px 8px;text-align:right}\
th{background:#eee}td.l{text-align:left}.anim{display:inline-block;margin:0 1em 1em 0;text-align:center;vertical-align:top}\
img{max-width:100%}.sw{display:inline-block;width:1em;height:1em;border:1px solid #555;vertical-align:middle;margin-right:.3em}\
.scale{display:inline-block;width:260px;height:14px;border:1px solid #555;vertical-align:middle;\
background:linear-gradient(to right,#000,#fff)}dl dt{font-weight:bold}dl dd{margin:0 0 .6em 1.5em}";

/// The demo page: the animation of the Seed 004 system by every method, the comparison with
/// the reference on S1 (`report`), the charts (`charts`, paths under `out`), and `sections`.
pub fn demo_index_html(
    anim: &[AnimationSummary],
    report: &SceneReport,
    charts: &[PathBuf],
    out: &Path,
    sections: &[Section],
) -> String {
    let mut s = format!(
        "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>texmap demo</title>\n<style>{STYLE}</style></head><body>\n"
    );
    s.push_str(
        "<h1>texmap demo: the Seed 004 silicate system</h1>\n\
<p>1,115 particles (409 O, 50 Si, 6 Al, 50 Mg, 500 H, 100 He) moved by a Lennard-Jones molecular-dynamics \
integrator (velocity Verlet), drawn on the CPU by four ways of drawing spheres and compared, pixel by pixel, \
with a reference ray tracer that intersects every sphere exactly.</p>\n\
<h2>The methods</h2>\n<dl>\n\
<dt>polygon</dt><dd>Each sphere tessellated into triangles (finer for spheres that look bigger) and \
rasterised: the classical baseline every paper compares against.</dd>\n\
<dt>lut (Seed 002)</dt><dd>Sphere impostors from look-up images: each sphere is a square textured with a \
pre-shaded colour image and a depth image of a unit sphere, computed once per material (Seed 002: \
\"A fast rendering method for molecular models using colour and depth images\"). Exact for an \
orthographic camera; with perspective the silhouette and shading drift away from the centre of view.</dd>\n\
<dt>template (Seed 004)</dt><dd>Template-texture billboards for large particle sets: each particle is a \
disc textured with a window cut from one template texture, so that the highlight moves with the view \
direction (Seed 004). The cheapest; its shading is a pseudo-shading.</dd>\n\
<dt>raycast</dt><dd>Per-pixel ray–sphere intersection over each sphere's exact screen footprint: exact \
silhouette, depth and normal, as the reference, at impostor cost.</dd>\n\
<dt>reference (reftrace)</dt><dd>A BVH ray tracer, one ray through each pixel centre, with the same camera \
and lighting: the image every method is measured against.</dd>\n</dl>\n",
    );
    // Element legend.
    s.push_str("<p><b>Element colours</b> (Jmol CPK): ");
    for (e, count, radius) in SEED004_SPECIES {
        let [r, g, b] = e.cpk_srgb();
        s.push_str(&format!(
            "<span class=\"sw\" style=\"background:rgb({r},{g},{b})\"></span>{} ({count} particles, radius {radius} Å) &nbsp; ",
            e.symbol()
        ));
    }
    s.push_str("</p>\n");

    // Animation.
    s.push_str(
        "<h2>Animation</h2>\n<p><button onclick=\"play=!play\">play / pause</button> \
<input type=\"range\" id=\"slider\" min=\"0\" value=\"0\" oninput=\"show(+this.value)\"> frame <span id=\"fno\">0</span> \
&middot; the exact ray-cast animation as one movie file: <a href=\"md.apng\">md.apng</a> \
(<code>texmap movie frames/raycast -o md.mp4</code> makes an MP4)</p>\n",
    );
    for a in anim {
        s.push_str(&format!(
            "<div class=\"anim\"><img class=\"frame\" data-method=\"{m}\" src=\"frames/{m}/0000.png\" width=\"320\"><br>{m}: {ms:.2} ms/frame</div>\n",
            m = a.method,
            ms = a.ms_per_frame
        ));
    }
    s.push_str(
        "<p><small>Why the animation's ms/frame differ from the table below: the animation times each \
frame once (the first frame also builds the per-material look-up images and template pyramid, and a \
moving system keeps the caches cold), while the table reports the median of five runs of one frame \
after a warm-up run. Both are wall-clock times on this machine, which other work may share.</small></p>\n",
    );
    let n = anim.first().map(|a| a.frames).unwrap_or(0);
    s.push_str(&format!(
        "<script>\nconst N={n};let cur=0,play=true;const sl=document.getElementById('slider');sl.max=N-1;\n\
function show(i){{cur=i;sl.value=i;document.getElementById('fno').textContent=i;\
for(const im of document.querySelectorAll('img.frame')){{im.src='frames/'+im.dataset.method+'/'+String(i).padStart(4,'0')+'.png';}}}}\n\
setInterval(()=>{{if(play&&N>0)show((cur+1)%N);}},100);\n</script>\n"
    ));

    // The comparison table, and what its columns mean.
    s.push_str(&format!(
        "<h2>Speed against accuracy (scene S1, {}, reference: reftrace, 1 sample per pixel)</h2>\n\
<table><tr><th>method</th><th>ms/frame</th><th>PSNR dB</th><th>SSIM</th><th>depth err mean</th><th>depth err max</th><th>silhouette px</th></tr>\n",
        escape(&report.scene)
    ));
    for r in &report.records {
        let psnr = if r.psnr_db.is_infinite() {
            "∞ (identical)".to_string()
        } else {
            format!("{:.2}", r.psnr_db)
        };
        s.push_str(&format!(
            "<tr><td class=\"l\">{}</td><td>{:.3}</td><td>{psnr}</td><td>{:.4}</td><td>{:.3e}</td><td>{:.3e}</td><td>{:.3}</td></tr>\n",
            escape(&r.method), r.ms_per_frame, r.ssim, r.depth_err_mean, r.depth_err_max, r.silhouette_px
        ));
    }
    s.push_str(
        "</table>\n<dl>\n\
<dt>PSNR (dB)</dt><dd>Peak signal-to-noise ratio of the 8-bit sRGB image against the reference: \
10·log10(255² / mean squared error). Higher is better; every 6 dB halves the typical error; above about \
40 dB differences are hard to see, below about 25 dB they are obvious; ∞ means the images are identical \
(charts draw it at 100 dB with an open marker).</dd>\n\
<dt>SSIM</dt><dd>Structural similarity (0 to 1, 1 = identical): compares local brightness, contrast and \
structure in small windows, closer to what the eye notices than PSNR.</dd>\n\
<dt>depth err</dt><dd>Difference of the eye-space depth from the reference's where both drew something, in \
scene units (Å): mean and maximum. It matters when images are composited or depth-cued.</dd>\n\
<dt>silhouette px</dt><dd>Mean displacement, in pixels, of the objects' outlines from the reference's \
outlines (from pixels covered by one image and not the other).</dd>\n</dl>\n\
<p>Machine-readable: <a href=\"results.json\">results.json</a>, <a href=\"results.csv\">results.csv</a>, \
<a href=\"sweeps.csv\">sweeps.csv</a>.</p>\n",
    );

    // Images and the error colour scale.
    let gain = ERROR_GAIN;
    let sat = (255.0 / gain).ceil() as u32;
    s.push_str(&format!(
        "<h2>Images (S1): each method and its error against the reference</h2>\n\
<p><b>Error images:</b> the per-channel difference from the reference times {gain}: \
0 <span class=\"scale\"></span> {sat}+ levels of 255 (black = no error, white = a difference of {sat} \
or more in every channel; colour = the channel that differs). \
<span class=\"sw\" style=\"background:#f0f\"></span>magenta: the method covers a pixel the reference \
leaves empty; <span class=\"sw\" style=\"background:#0f0\"></span>green: the reference covers a pixel the \
method misses.</p>\n"
    ));
    let scene_dir = escape(&report.scene);
    s.push_str(&format!(
        "<div class=\"anim\"><img src=\"{scene_dir}/reference.png\" width=\"300\"><br>reference</div>\n"
    ));
    for run in &report.runs {
        let m = run.method.name();
        s.push_str(&format!(
            "<div class=\"anim\"><img src=\"{scene_dir}/{m}.png\" width=\"300\"><br>{m}</div>\
<div class=\"anim\"><img src=\"{scene_dir}/{m}_error.png\" width=\"300\"><br>{m} error</div>\n"
        ));
    }

    // Charts, with what each sweep varies.
    s.push_str(
        "<h2>Charts</h2>\n<p>The first chart places every method by speed and accuracy on S1. The sweeps \
find where each method breaks: each draws <b>one sphere</b> at 128×128 pixels and varies one thing, \
every method against the reference at each point.</p>\n<dl>\n\
<dt>fov</dt><dd>The horizontal field of view (0 = orthographic), the sphere kept at the same size on \
screen: how far each method tolerates perspective.</dd>\n\
<dt>off_axis</dt><dd>The angle of the sphere away from the view axis under a 90° field of view: \
perspective distortion toward the image edge.</dd>\n\
<dt>eye_distance</dt><dd>The eye's distance from the sphere's centre in sphere radii, down to the eye \
almost touching it.</dd>\n\
<dt>screen_radius</dt><dd>The sphere's radius on screen in pixels, from sub-pixel to filling the view: \
where look-up images and templates run out of resolution.</dd>\n</dl>\n\
<p>Lines of methods that agree lie on top of each other: earlier series are drawn wider and every method \
has its own marker shape, so a hidden line shows as an outline.</p>\n",
    );
    for c in charts
        .iter()
        .filter(|c| c.extension().is_some_and(|e| e == "svg"))
    {
        s.push_str(&format!(
            "<div><img src=\"{}\" width=\"720\"></div>\n",
            escape(&rel(c, out))
        ));
    }
    for sec in sections {
        s.push_str(&format!("<h2>{}</h2>\n{}\n", escape(&sec.title), sec.html));
    }
    s.push_str("</body></html>\n");
    s
}

/// The environment-mapping section (Seed 003): what the methods are, their measured error and
/// time (`records` of [`crate::envmap::run`]), one image per method (`images`: names as in
/// [`crate::envmap::demo_frames`], files `<dir>/<name>.png`) and the study's charts
/// (`<dir>/envmap_*.svg`). `dir` is relative to the page.
pub fn envmap_section(
    records: &[crate::envmap::EnvRecord],
    images: &[String],
    dir: &str,
) -> Section {
    let dir = escape(dir);
    let mut s = String::from(
        "<p>A mirror sphere among orbiting objects in a striped tunnel (after Seed 003's demo). \
<b>Seed 003</b> re-renders a <i>sphere map</i> around the mirror every frame: the other objects' \
triangles are rasterised straight into sphere-map space around the target's centre, then the target \
looks its reflections up in that map. The alternatives engines use: a static sphere map of the \
environment only (per pixel, or per vertex as in 1998, whose rim \"sparkles\"), a dynamic cube map \
(six faces), a dual-paraboloid map (two) and a box-projected cube map (parallax-corrected for nearby \
walls). The reference ray-traces the mirror exactly.</p>\n\
<table><tr><th>method</th><th>PSNR dB (target pixels)</th><th>PSNR dB vs environment only</th>\
<th>map update ms</th><th>draw ms</th></tr>\n",
    );
    for r in records.iter().filter(|r| r.study == "methods") {
        s.push_str(&format!(
            "<tr><td class=\"l\">{}</td><td>{:.2}</td><td>{:.2}</td><td>{:.2}</td><td>{:.2}</td></tr>\n",
            escape(&r.method),
            r.psnr_db,
            r.psnr_env_only_db,
            r.update_ms,
            r.draw_ms
        ));
    }
    s.push_str(
        "</table>\n<p>PSNR is measured over the mirror's pixels only. \"vs environment only\" compares \
with a reference traced without the other objects: what a static map of the surroundings can at best \
reach, which is why the static maps score well there and badly against the full scene. Times are \
wall-clock medians of a few frames at a small size; the criterion bench (<code>cargo bench --bench \
envmap</code>) gives the figures to quote.</p>\n",
    );
    for name in images {
        let n = escape(name);
        s.push_str(&format!(
            "<div class=\"anim\"><img src=\"{dir}/{n}.png\" width=\"240\"><br>{n}</div>\n"
        ));
    }
    s.push_str(
        "<p>Charts: the error against the angle of incidence (the sphere map's sampling collapses \
toward the silhouette), against the distance of a reflected object (a map has one centre: \
Seed 003 is exact only there), against the map's resolution, for refraction, and for time-sliced \
cube maps (N of the six faces redrawn per frame on the moving scene: the update cost against the \
error of faces drawn up to a few frames earlier).</p>\n",
    );
    for study in ["angle", "distance", "resolution", "refraction", "staleness"] {
        s.push_str(&format!(
            "<div><img src=\"{dir}/envmap_{study}.svg\" width=\"720\"></div>\n"
        ));
    }
    Section {
        title: "Environment mapping (Seed 003)".into(),
        html: s,
    }
}
