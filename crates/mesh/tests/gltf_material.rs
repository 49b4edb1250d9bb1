//! glTF base colours (`read_gltf_base_color`): a texture embedded as a data URI in a file written
//! by another program (Khronos' BoxTextured, from COLLADA2GLTF) against Pillow's reading of the
//! same PNG, a texture embedded in a `.glb` buffer view, a material without texture, and damage.

use std::path::PathBuf;
use texmap_mesh::{TriMesh, read_gltf, read_gltf_base_color, write_glb};

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

#[test]
fn box_textured_reads_its_embedded_png() {
    let path = data("BoxTextured.gltf");
    let meshes = read_gltf(&path).unwrap();
    assert_eq!(meshes.len(), 1);
    assert_eq!(meshes[0].positions.len(), 24);
    assert_eq!(meshes[0].triangles.len(), 12);
    let uvs = meshes[0].uvs.as_ref().unwrap();
    let umax = uvs.iter().map(|u| u.x).fold(0.0f32, f32::max);
    assert_eq!(umax, 6.0); // the accessor's max: the logo repeats along the faces
    let bc = read_gltf_base_color(&path).unwrap().unwrap();
    assert_eq!(bc.factor, [1.0; 4]); // glTF's default
    assert_eq!(bc.tex_coord, 0);
    let t = bc.texture.unwrap();
    assert_eq!(t.dimensions(), (211, 211));
    // Pillow's reading of the same PNG (tests/data/README.md).
    assert_eq!(t.get_pixel(0, 0).0, [220, 220, 220, 255]);
    assert_eq!(t.get_pixel(105, 105).0, [255, 255, 255, 255]);
    assert_eq!(t.get_pixel(50, 150).0, [92, 135, 39, 255]);
    let colours: std::collections::HashSet<[u8; 4]> = t.pixels().map(|p| p.0).collect();
    assert_eq!(colours.len(), 59);
}

#[test]
fn a_glb_texture_in_a_buffer_view_reads_back() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = TriMesh::new(
        vec![
            glam::Vec3::ZERO,
            glam::Vec3::X,
            glam::Vec3::Y,
            glam::Vec3::new(1.0, 1.0, 0.0),
        ],
        vec![[0, 1, 2], [2, 1, 3]],
    )
    .unwrap()
    .with_uvs(vec![
        glam::Vec2::ZERO,
        glam::Vec2::X,
        glam::Vec2::Y,
        glam::Vec2::ONE,
    ])
    .unwrap();
    let img = image::RgbaImage::from_fn(37, 19, |x, y| {
        image::Rgba([(x * 7) as u8, (y * 13) as u8, (x ^ y) as u8, 200])
    });
    let path = dir.path().join("quad.glb");
    write_glb(&path, &mesh, Some(&img)).unwrap();
    let bc = read_gltf_base_color(&path).unwrap().unwrap();
    let t = bc.texture.unwrap();
    assert!(t == img);
    // Without a texture, no material at all.
    let bare = dir.path().join("bare.glb");
    write_glb(&bare, &mesh, None).unwrap();
    let bc = read_gltf_base_color(&bare).unwrap();
    assert!(bc.is_none_or(|b| b.texture.is_none()));
}

#[test]
fn damaged_images_are_named_errors() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(data("BoxTextured.gltf")).unwrap();
    // Corrupt the PNG inside the data URI (its CRCs no longer match).
    let at = text.find("iVBORw0KGgo").unwrap() + 200;
    let mut bad = text.clone();
    bad.replace_range(at..at + 8, "AAAAAAAA");
    let p = dir.path().join("bad.gltf");
    std::fs::write(&p, bad).unwrap();
    let e = read_gltf_base_color(&p).unwrap_err().to_string();
    assert!(e.contains("bad.gltf") && e.contains("image 0"), "{e}");
    // An image file that is not there.
    let missing = text.replace(
        &text[text.find("data:image/png").unwrap()
            ..text
                .find("\"\n        }\n    ],\n    \"samplers\"")
                .unwrap()],
        "logo.png",
    );
    let p = dir.path().join("missing.gltf");
    std::fs::write(&p, missing).unwrap();
    let e = read_gltf_base_color(&p).unwrap_err().to_string();
    assert!(e.contains("missing.gltf") && e.contains("image 0"), "{e}");
}
