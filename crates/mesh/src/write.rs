//! Writing meshes: binary glTF 2.0 (`.glb`, one mesh, the texture embedded as PNG) and Wavefront
//! OBJ with its MTL and PNG beside it.
//!
//! The glTF document is built from the `gltf` crate's `gltf::json` types and packed with
//! `gltf::binary::Glb`, so the output is what the same crate reads back. Layout of the binary
//! chunk: positions (`VEC3` f32, with the `min`/`max` glTF requires), texture coordinates
//! (`VEC2` f32, `v` down the image as glTF wants), normals if any, `u32` indices, then the PNG —
//! each 4-byte aligned. Every file is written to a temporary name in its directory and renamed,
//! so a failed export never leaves a partial file.

use crate::{MeshError, TriMesh};
use gltf::json;
use gltf::json::validation::{Checked, USize64};
use std::io::Write;
use std::path::{Path, PathBuf};

fn io_err(path: &Path) -> impl FnOnce(std::io::Error) -> MeshError + '_ {
    move |source| MeshError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// Write `bytes` to `path` through a temporary file in the same directory and a rename.
fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), MeshError> {
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let name = path.file_name().ok_or_else(|| MeshError::Io {
        path: path.to_path_buf(),
        source: std::io::Error::new(std::io::ErrorKind::InvalidInput, "no file name"),
    })?;
    let tmp: PathBuf = dir.join(format!(
        ".{}.tmp-{}",
        name.to_string_lossy(),
        std::process::id()
    ));
    let result = (|| {
        let mut f = std::fs::File::create(&tmp).map_err(io_err(&tmp))?;
        f.write_all(bytes).map_err(io_err(&tmp))?;
        f.sync_all().map_err(io_err(&tmp))?;
        std::fs::rename(&tmp, path).map_err(io_err(path))
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

fn png_bytes(img: &image::RgbaImage, source: &str) -> Result<Vec<u8>, MeshError> {
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png)
        .map_err(|e| MeshError::Gltf {
            source: source.to_string(),
            message: format!("PNG encoding: {e}"),
        })?;
    Ok(out.into_inner())
}

fn typed<T: serde::de::DeserializeOwned>(
    v: serde_json::Value,
    source: &str,
) -> Result<T, MeshError> {
    serde_json::from_value(v).map_err(|e| MeshError::Gltf {
        source: source.to_string(),
        message: e.to_string(),
    })
}

/// Write `mesh` (and its texture, if given: the mesh must then have uvs) as a binary glTF 2.0 file.
pub fn write_glb(
    path: impl AsRef<Path>,
    mesh: &TriMesh,
    texture: Option<&image::RgbaImage>,
) -> Result<(), MeshError> {
    let path = path.as_ref();
    let source = path.display().to_string();
    mesh.validate(&source, 0)?;
    if mesh.triangles.is_empty() {
        return Err(MeshError::NoTriangles { source });
    }
    let mut bin: Vec<u8> = Vec::new();
    let mut root = json::Root::default();
    let buffer = json::Index::<json::Buffer>::new(0);
    // Append a 4-byte aligned view over `bytes`.
    let view = |root: &mut json::Root,
                bin: &mut Vec<u8>,
                bytes: &[u8],
                target: Option<json::buffer::Target>| {
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        let offset = bin.len();
        bin.extend_from_slice(bytes);
        root.push(json::buffer::View {
            buffer,
            byte_length: USize64(bytes.len() as u64),
            byte_offset: Some(USize64(offset as u64)),
            byte_stride: None,
            name: None,
            target: target.map(Checked::Valid),
            extensions: None,
            extras: Default::default(),
        })
    };
    let f32_bytes = |v: &[f32]| v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>();
    let (lo, hi) = mesh.bounds().expect("a mesh with triangles has vertices");
    let pos = f32_bytes(
        &mesh
            .positions
            .iter()
            .flat_map(|p| p.to_array())
            .collect::<Vec<_>>(),
    );
    let pv = view(
        &mut root,
        &mut bin,
        &pos,
        Some(json::buffer::Target::ArrayBuffer),
    );
    let n = mesh.positions.len();
    let pa: json::Accessor = typed(
        serde_json::json!({"bufferView": pv.value(), "componentType": 5126, "count": n, "type": "VEC3",
            "min": lo.to_array(), "max": hi.to_array()}),
        &source,
    )?;
    let pa = root.push(pa);
    let mut attributes = serde_json::json!({"POSITION": pa.value()});
    // One f32 vertex attribute: its view, its accessor, its entry in the primitive's attributes.
    let mut attribute = |name: &str, kind: &str, values: Vec<f32>| -> Result<(), MeshError> {
        let v = view(
            &mut root,
            &mut bin,
            &f32_bytes(&values),
            Some(json::buffer::Target::ArrayBuffer),
        );
        let a: json::Accessor = typed(
            serde_json::json!({"bufferView": v.value(), "componentType": 5126, "count": n, "type": kind}),
            &source,
        )?;
        attributes[name] = root.push(a).value().into();
        Ok(())
    };
    if let Some(uvs) = &mesh.uvs {
        attribute(
            "TEXCOORD_0",
            "VEC2",
            uvs.iter().flat_map(|p| p.to_array()).collect(),
        )?;
    }
    if let Some(normals) = &mesh.normals {
        let unit = normals
            .iter()
            .flat_map(|p| p.normalize_or_zero().to_array());
        attribute("NORMAL", "VEC3", unit.collect())?;
    }
    let idx: Vec<u8> = mesh
        .triangles
        .iter()
        .flatten()
        .flat_map(|i| i.to_le_bytes())
        .collect();
    let iv = view(
        &mut root,
        &mut bin,
        &idx,
        Some(json::buffer::Target::ElementArrayBuffer),
    );
    let ia: json::Accessor = typed(
        serde_json::json!({"bufferView": iv.value(), "componentType": 5125, "count": mesh.triangles.len() * 3, "type": "SCALAR"}),
        &source,
    )?;
    let ia = root.push(ia);
    let mut material = serde_json::json!({"name": "terrain", "doubleSided": true,
        "pbrMetallicRoughness": {"metallicFactor": 0.0, "roughnessFactor": 1.0}});
    if let Some(img) = texture {
        if mesh.uvs.is_none() {
            return Err(MeshError::Gltf {
                source,
                message: "a texture needs texture coordinates on the mesh".into(),
            });
        }
        let png = png_bytes(img, &source)?;
        let v = view(&mut root, &mut bin, &png, None);
        let image: json::Image = typed(
            serde_json::json!({"bufferView": v.value(), "mimeType": "image/png"}),
            &source,
        )?;
        let image = root.push(image);
        let sampler: json::texture::Sampler = typed(
            serde_json::json!({"magFilter": 9729, "minFilter": 9987, "wrapS": 33071, "wrapT": 33071}),
            &source,
        )?;
        let sampler = root.push(sampler);
        let tex: json::Texture = typed(
            serde_json::json!({"source": image.value(), "sampler": sampler.value()}),
            &source,
        )?;
        let tex = root.push(tex);
        material["pbrMetallicRoughness"]["baseColorTexture"] =
            serde_json::json!({"index": tex.value()});
    }
    let material = root.push(typed::<json::Material>(material, &source)?);
    let prim = serde_json::json!({"attributes": attributes, "indices": ia.value(), "material": material.value(), "mode": 4});
    let m: json::Mesh = typed(serde_json::json!({"primitives": [prim]}), &source)?;
    let m = root.push(m);
    let node: json::Node = typed(serde_json::json!({"mesh": m.value()}), &source)?;
    let node = root.push(node);
    let scene: json::Scene = typed(serde_json::json!({"nodes": [node.value()]}), &source)?;
    root.scene = Some(root.push(scene));
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    root.push(json::Buffer {
        byte_length: USize64(bin.len() as u64),
        name: None,
        uri: None,
        extensions: None,
        extras: Default::default(),
    });
    let json_bytes = root.to_vec().map_err(|e| MeshError::Gltf {
        source: source.clone(),
        message: e.to_string(),
    })?;
    let mut json_bytes = json_bytes;
    while !json_bytes.len().is_multiple_of(4) {
        json_bytes.push(b' ');
    }
    let glb = gltf::binary::Glb {
        header: gltf::binary::Header {
            magic: *b"glTF",
            version: 2,
            length: (12 + 8 + json_bytes.len() + 8 + bin.len()) as u32,
        },
        json: std::borrow::Cow::Owned(json_bytes),
        bin: Some(std::borrow::Cow::Owned(bin)),
    };
    let bytes = glb.to_vec().map_err(|e| MeshError::Gltf {
        source: source.clone(),
        message: e.to_string(),
    })?;
    write_atomic(path, &bytes)
}

/// Write `mesh` as Wavefront OBJ; with a texture, also `<stem>.mtl` and `<stem>.png` beside it.
/// OBJ's `v` grows upwards, so texture coordinates are written as `1 − v`.
pub fn write_obj(
    path: impl AsRef<Path>,
    mesh: &TriMesh,
    texture: Option<&image::RgbaImage>,
) -> Result<(), MeshError> {
    use std::fmt::Write as _;
    let path = path.as_ref();
    let source = path.display().to_string();
    mesh.validate(&source, 0)?;
    if mesh.triangles.is_empty() {
        return Err(MeshError::NoTriangles { source });
    }
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "mesh".into());
    let mut s = String::new();
    if texture.is_some() {
        if mesh.uvs.is_none() {
            return Err(MeshError::Obj {
                source,
                message: "a texture needs texture coordinates on the mesh".into(),
            });
        }
        let _ = writeln!(s, "mtllib {stem}.mtl\nusemtl terrain");
    }
    for p in &mesh.positions {
        let _ = writeln!(s, "v {} {} {}", p.x, p.y, p.z);
    }
    if let Some(uvs) = &mesh.uvs {
        for t in uvs {
            let _ = writeln!(s, "vt {} {}", t.x, 1.0 - t.y);
        }
    }
    if let Some(ns) = &mesh.normals {
        for n in ns {
            let _ = writeln!(s, "vn {} {} {}", n.x, n.y, n.z);
        }
    }
    let (has_t, has_n) = (mesh.uvs.is_some(), mesh.normals.is_some());
    for t in &mesh.triangles {
        s.push('f');
        for &i in t {
            let i = i + 1;
            let _ = match (has_t, has_n) {
                (true, true) => write!(s, " {i}/{i}/{i}"),
                (true, false) => write!(s, " {i}/{i}"),
                (false, true) => write!(s, " {i}//{i}"),
                (false, false) => write!(s, " {i}"),
            };
        }
        s.push('\n');
    }
    if let Some(img) = texture {
        let dir = path.parent().unwrap_or(Path::new(""));
        write_atomic(&dir.join(format!("{stem}.png")), &png_bytes(img, &source)?)?;
        let mtl = format!(
            "newmtl terrain\nKa 1 1 1\nKd 1 1 1\nKs 0 0 0\nd 1\nillum 1\nmap_Kd {stem}.png\n"
        );
        write_atomic(&dir.join(format!("{stem}.mtl")), mtl.as_bytes())?;
    }
    write_atomic(path, s.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Vec2, Vec3};

    fn quad() -> TriMesh {
        TriMesh::new(
            vec![
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(10.0, 1.0, 0.0),
                Vec3::new(10.0, 2.0, 5.0),
                Vec3::new(0.0, -3.0, 5.0),
            ],
            vec![[0, 2, 1], [0, 3, 2]],
        )
        .unwrap()
        .with_uvs(vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(0.0, 1.0),
        ])
        .unwrap()
    }

    #[test]
    fn glb_reads_back_with_texture() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("q.glb");
        let img = image::RgbaImage::from_fn(8, 4, |x, y| {
            image::Rgba([x as u8 * 30, y as u8 * 60, 7, 255])
        });
        write_glb(&p, &quad(), Some(&img)).unwrap();
        let back = crate::read_gltf(&p).unwrap();
        assert_eq!(back.len(), 1);
        assert_eq!(back[0].positions.len(), 4);
        assert_eq!(back[0].triangles.len(), 2);
        assert_eq!(
            back[0].bounds(),
            Some((Vec3::new(0.0, -3.0, 0.0), Vec3::new(10.0, 2.0, 5.0)))
        );
        assert_eq!(back[0].uvs.as_ref().unwrap()[2], Vec2::new(1.0, 1.0));
        // The embedded image, through the gltf crate's own importer.
        let (_, _, images) = gltf::import(&p).unwrap();
        assert_eq!((images[0].width, images[0].height), (8, 4));
        let px = &images[0].pixels[(8 * 3 + 5) * 4..(8 * 3 + 5) * 4 + 4];
        assert_eq!(px, &[150, 60 * 3, 7, 255]);
        assert_eq!(
            std::fs::read_dir(dir.path()).unwrap().count(),
            1,
            "no temporary left"
        );
    }

    #[test]
    fn obj_reads_back() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("q.obj");
        write_obj(&p, &quad(), Some(&image::RgbaImage::new(2, 2))).unwrap();
        let back = crate::read_obj(&p).unwrap();
        assert_eq!(back[0].positions.len(), 4);
        // The reader may reorder vertices: find (10, 1, 0) and check its (glTF-convention) uv.
        let i = back[0]
            .positions
            .iter()
            .position(|p| *p == Vec3::new(10.0, 1.0, 0.0))
            .unwrap();
        assert_eq!(back[0].uvs.as_ref().unwrap()[i], Vec2::new(1.0, 0.0));
        assert!(dir.path().join("q.mtl").exists() && dir.path().join("q.png").exists());
    }
}
