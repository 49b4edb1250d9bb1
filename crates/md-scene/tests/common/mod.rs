//! Shared by the mesh tests: the reference ray tracer's image of a `MolMesh`.

use texmap_core::camera::Camera;
use texmap_core::frame::Frame;
use texmap_core::shade::{Lighting, Material};
use texmap_md_scene::surface::MolMesh;
use texmap_reftrace::{MeshShading, RenderOptions, SceneBuilder, SurfaceMaterial};

/// `mesh` traced by reftrace: each material's triangles as one mesh shaded by the vertex
/// normals, `samples` x `samples` stratified samples a pixel, over `background`.
pub fn traced(
    mesh: &MolMesh,
    materials: &[Material],
    camera: &Camera,
    lighting: Lighting,
    samples: u32,
    background: [u8; 4],
) -> Frame {
    let mut b = SceneBuilder::new();
    for (k, group) in mesh
        .by_kind(materials.len())
        .iter()
        .enumerate()
        .take(materials.len())
    {
        if !group.is_empty() {
            b.add_mesh_shaded(
                &mesh.positions,
                group.as_flattened(),
                None,
                Some(&mesh.normals),
                MeshShading::VertexNormals,
                k as u32,
            )
            .unwrap();
        }
    }
    let mats: Vec<SurfaceMaterial> = materials
        .iter()
        .map(|&m| SurfaceMaterial::opaque(m))
        .collect();
    let mut o = RenderOptions::new(lighting, &mats);
    o.samples_per_axis = samples;
    o.background = texmap_core::color::srgb8_to_linear_rgb(background);
    b.build().render(camera, &o).unwrap()
}
