//! Mesh reading: Wavefront OBJ (tobj) and glTF 2.0 (gltf), from files or from bytes in memory.
//!
//! Both readers return one [`TriMesh`] per mesh (OBJ object/group, glTF primitive) with
//! positions, triangle indices and, when present, the first set of texture coordinates and the
//! vertex normals (glTF normals are carried through the inverse transpose of the node transform;
//! the consumer decides whether they are used). OBJ faces
//! are triangulated and re-indexed so that positions and uvs share one index. glTF meshes are
//! placed by their nodes' world transforms in the default scene (or the first one); meshes not
//! referenced by any node are not returned. Only triangle-list primitives are read; other modes
//! are an error. Images and materials are not read. Bytes are given a `source` name that every
//! error message carries.

use std::path::Path;

use glam::{Mat4, Vec2, Vec3};

use crate::{MeshError, TriMesh};

/// Read the OBJ file at `path` (materials are not read).
pub fn read_obj(path: impl AsRef<Path>) -> Result<Vec<TriMesh>, MeshError> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|source| MeshError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    read_obj_bytes(&bytes, &path.display().to_string())
}

/// Parse OBJ text held in memory; `source` names it in errors.
pub fn read_obj_bytes(bytes: &[u8], source: &str) -> Result<Vec<TriMesh>, MeshError> {
    let opts = tobj::LoadOptions {
        single_index: true,
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let mut reader = std::io::BufReader::new(bytes);
    let (models, _materials) =
        tobj::load_obj_buf(&mut reader, &opts, |_| Err(tobj::LoadError::OpenFileFailed)).map_err(
            |e| MeshError::Obj {
                source: source.to_string(),
                message: e.to_string(),
            },
        )?;
    let mut out = Vec::with_capacity(models.len());
    for (k, model) in models.into_iter().enumerate() {
        let m = model.mesh;
        let bad = |attribute, len| MeshError::AttributeLength {
            source: source.to_string(),
            mesh: k,
            attribute,
            len,
            expected: 0,
        };
        if m.positions.len() % 3 != 0 {
            return Err(bad("positions", m.positions.len()));
        }
        let positions: Vec<Vec3> = m
            .positions
            .chunks_exact(3)
            .map(|p| Vec3::new(p[0], p[1], p[2]))
            .collect();
        let uvs = if m.texcoords.is_empty() {
            None
        } else {
            if m.texcoords.len() != 2 * positions.len() {
                return Err(bad("texcoords", m.texcoords.len()));
            }
            // OBJ's v axis points up; ours (like glTF's) points down the rows.
            Some(
                m.texcoords
                    .chunks_exact(2)
                    .map(|t| Vec2::new(t[0], 1.0 - t[1]))
                    .collect(),
            )
        };
        let normals = if m.normals.is_empty() {
            None
        } else {
            if m.normals.len() != 3 * positions.len() {
                return Err(bad("normals", m.normals.len()));
            }
            Some(
                m.normals
                    .chunks_exact(3)
                    .map(|n| Vec3::new(n[0], n[1], n[2]))
                    .collect(),
            )
        };
        let mesh = TriMesh {
            positions,
            triangles: triangles(m.indices, source, k)?,
            uvs,
            normals,
        };
        mesh.validate(source, k)?;
        if !mesh.triangles.is_empty() {
            out.push(mesh);
        }
    }
    if out.is_empty() {
        return Err(MeshError::NoTriangles {
            source: source.to_string(),
        });
    }
    Ok(out)
}

/// Read a glTF (`.gltf` with its buffers resolved next to it, or `.glb`) file.
pub fn read_gltf(path: impl AsRef<Path>) -> Result<Vec<TriMesh>, MeshError> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|source| MeshError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    read_gltf_impl(&bytes, &path.display().to_string(), path.parent())
}

/// Parse glTF held in memory (a `.glb`, or `.gltf` JSON whose buffers are embedded as data URIs);
/// `source` names it in errors. External buffer files cannot be resolved from memory.
pub fn read_gltf_bytes(bytes: &[u8], source: &str) -> Result<Vec<TriMesh>, MeshError> {
    read_gltf_impl(bytes, source, None)
}

fn read_gltf_impl(
    bytes: &[u8],
    source: &str,
    base: Option<&Path>,
) -> Result<Vec<TriMesh>, MeshError> {
    let gerr = |e: gltf::Error| MeshError::Gltf {
        source: source.to_string(),
        message: e.to_string(),
    };
    let gltf = gltf::Gltf::from_slice(bytes).map_err(gerr)?;
    let gltf::Gltf { document, blob } = gltf;
    let base = base.map(|b| {
        if b.as_os_str().is_empty() {
            Path::new(".")
        } else {
            b
        }
    });
    let buffers = gltf::import_buffers(&document, base, blob).map_err(gerr)?;
    let mut out = Vec::new();
    let scene = document
        .default_scene()
        .or_else(|| document.scenes().next());
    if let Some(scene) = scene {
        // Walk the node tree with an explicit stack (no recursion on untrusted depth).
        let mut stack: Vec<(gltf::Node, Mat4)> =
            scene.nodes().map(|n| (n, Mat4::IDENTITY)).collect();
        let mut visited = 0usize;
        while let Some((node, parent)) = stack.pop() {
            visited += 1;
            if visited > 1_000_000 {
                return Err(MeshError::Gltf {
                    source: source.to_string(),
                    message: "node hierarchy too large or cyclic".to_string(),
                });
            }
            let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
            if let Some(mesh) = node.mesh() {
                read_gltf_mesh(&mesh, &buffers, world, source, &mut out)?;
            }
            for child in node.children() {
                stack.push((child, world));
            }
        }
    }
    if out.is_empty() {
        return Err(MeshError::NoTriangles {
            source: source.to_string(),
        });
    }
    Ok(out)
}

fn read_gltf_mesh(
    mesh: &gltf::Mesh,
    buffers: &[gltf::buffer::Data],
    world: Mat4,
    source: &str,
    out: &mut Vec<TriMesh>,
) -> Result<(), MeshError> {
    for prim in mesh.primitives() {
        let k = out.len();
        if prim.mode() != gltf::mesh::Mode::Triangles {
            return Err(MeshError::UnsupportedPrimitive {
                source: source.to_string(),
                mesh: mesh.index(),
                mode: format!("{:?}", prim.mode()),
            });
        }
        let reader = prim.reader(|b| buffers.get(b.index()).map(|d| d.0.as_slice()));
        let Some(pos) = reader.read_positions() else {
            continue;
        };
        let positions: Vec<Vec3> = pos
            .map(|p| world.transform_point3(Vec3::from_array(p)))
            .collect();
        let indices: Vec<u32> = match reader.read_indices() {
            Some(ix) => ix.into_u32().collect(),
            None => (0..positions.len() as u32).collect(),
        };
        let uvs = reader
            .read_tex_coords(0)
            .map(|t| t.into_f32().map(Vec2::from_array).collect::<Vec<_>>());
        if let Some(uv) = &uvs
            && uv.len() != positions.len()
        {
            return Err(MeshError::AttributeLength {
                source: source.to_string(),
                mesh: k,
                attribute: "TEXCOORD_0",
                len: uv.len(),
                expected: positions.len(),
            });
        }
        // Normals go through the inverse transpose of the node transform (unit length is
        // restored when the mesh is added).
        let normal_matrix = glam::Mat3::from_mat4(world).inverse().transpose();
        let normals = reader.read_normals().map(|n| {
            n.map(|v| normal_matrix * Vec3::from_array(v))
                .collect::<Vec<_>>()
        });
        if let Some(n) = &normals
            && n.len() != positions.len()
        {
            return Err(MeshError::AttributeLength {
                source: source.to_string(),
                mesh: k,
                attribute: "NORMAL",
                len: n.len(),
                expected: positions.len(),
            });
        }
        let m = TriMesh {
            positions,
            triangles: triangles(indices, source, k)?,
            uvs,
            normals,
        };
        m.validate(source, k)?;
        if !m.triangles.is_empty() {
            out.push(m);
        }
    }
    Ok(())
}

/// A flat index list as triangles; its length must be a multiple of three. Index values are
/// checked by [`TriMesh::validate`] at the file boundary, so that the error names the file.
fn triangles(indices: Vec<u32>, source: &str, mesh: usize) -> Result<Vec<[u32; 3]>, MeshError> {
    if !indices.len().is_multiple_of(3) {
        return Err(MeshError::IndicesNotTriangles {
            source: source.to_string(),
            mesh,
            len: indices.len(),
        });
    }
    Ok(indices
        .chunks_exact(3)
        .map(|t| [t[0], t[1], t[2]])
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    const QUAD_OBJ: &str = "# a unit quad\n\
        v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n\
        vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
        f 1/1 2/2 3/3 4/4\n";

    #[test]
    fn obj_quad_is_two_triangles_with_flipped_v() {
        let m = read_obj_bytes(QUAD_OBJ.as_bytes(), "quad.obj").unwrap();
        assert_eq!(m.len(), 1);
        assert_eq!(m[0].triangles.len(), 2);
        assert_eq!(m[0].positions.len(), 4);
        let uvs = m[0].uvs.as_ref().unwrap();
        // Vertex (1, 1, 0) has vt (1, 1) -> our (1, 0).
        let k = m[0]
            .positions
            .iter()
            .position(|p| *p == Vec3::new(1.0, 1.0, 0.0))
            .unwrap();
        assert_eq!(uvs[k], Vec2::new(1.0, 0.0));
    }

    #[test]
    fn obj_and_gltf_vertex_normals_are_read() {
        // OBJ: a triangle whose vertices carry three different normals.
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvn 1 0 0\nvn 0 1 0\n\
            f 1//1 2//2 3//3\n";
        let m = read_obj_bytes(text.as_bytes(), "n.obj").unwrap();
        let n = m[0].normals.as_ref().expect("normals read");
        for (p, want) in [
            (Vec3::ZERO, Vec3::Z),
            (Vec3::X, Vec3::X),
            (Vec3::Y, Vec3::Y),
        ] {
            let k = m[0].positions.iter().position(|q| *q == p).unwrap();
            assert_eq!(n[k], want, "normal of vertex {p}");
        }
        // No vn lines: no normals.
        assert!(
            read_obj_bytes(QUAD_OBJ.as_bytes(), "q.obj").unwrap()[0]
                .normals
                .is_none()
        );
        // glTF without NORMAL: none.
        let g = read_gltf_bytes(triangle_gltf([0.0; 3]).as_bytes(), "t.gltf").unwrap();
        assert!(g[0].normals.is_none());
    }

    #[test]
    fn obj_errors_name_the_source() {
        let e = read_obj_bytes(b"v 0 0 0\nf 1 2 3\n", "broken.obj").unwrap_err();
        assert!(e.to_string().contains("broken.obj"), "{e}");
        let e = read_obj_bytes(b"# nothing\n", "empty.obj").unwrap_err();
        assert!(matches!(e, MeshError::NoTriangles { .. }), "{e}");
        let e = read_obj("/nonexistent/dir/x.obj").unwrap_err();
        assert!(e.to_string().contains("/nonexistent/dir/x.obj"), "{e}");
    }

    /// A one-triangle glTF with an embedded base64 buffer (positions f32 x3, indices u16 x3).
    fn triangle_gltf(translation: [f32; 3]) -> String {
        let mut buf = Vec::new();
        for p in [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
            for c in p {
                buf.extend_from_slice(&c.to_le_bytes());
            }
        }
        for i in [0u16, 1, 2] {
            buf.extend_from_slice(&i.to_le_bytes());
        }
        buf.extend_from_slice(&[0, 0]); // pad to 4 bytes
        let b64 = base64_encode(&buf);
        format!(
            r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],
            "nodes":[{{"mesh":0,"translation":[{},{},{}]}}],
            "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],
            "buffers":[{{"byteLength":{},"uri":"data:application/octet-stream;base64,{}"}}],
            "bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":6}}],
            "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}},
                         {{"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"}}]}}"#,
            translation[0],
            translation[1],
            translation[2],
            buf.len(),
            b64
        )
    }

    /// A one-triangle glTF with a NORMAL accessor, placed by a node with scale `scale`.
    fn normal_triangle_gltf(scale: [f32; 3], normal: [f32; 3]) -> String {
        let mut buf = Vec::new();
        for p in [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
            for c in p {
                buf.extend_from_slice(&c.to_le_bytes());
            }
        }
        for _ in 0..3 {
            for c in normal {
                buf.extend_from_slice(&c.to_le_bytes());
            }
        }
        format!(
            r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],
            "nodes":[{{"mesh":0,"scale":[{},{},{}]}}],
            "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0,"NORMAL":1}}}}]}}],
            "buffers":[{{"byteLength":{},"uri":"data:application/octet-stream;base64,{}"}}],
            "bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":36}}],
            "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}},
                         {{"bufferView":1,"componentType":5126,"count":3,"type":"VEC3"}}]}}"#,
            scale[0],
            scale[1],
            scale[2],
            buf.len(),
            base64_encode(&buf)
        )
    }

    #[test]
    fn gltf_normals_follow_the_inverse_transpose_of_the_node_transform() {
        // Scale x by 2: a normal (1, 1, 0)/√2 becomes (1/2, 1, 0) up to length, i.e. it stays
        // perpendicular to the scaled surface, unlike a normal scaled like a position.
        let s = std::f32::consts::FRAC_1_SQRT_2;
        let text = normal_triangle_gltf([2.0, 1.0, 1.0], [s, s, 0.0]);
        let m = read_gltf_bytes(text.as_bytes(), "n.gltf").unwrap();
        let n = m[0].normals.as_ref().expect("normals read")[0].normalize();
        let want = Vec3::new(0.5, 1.0, 0.0).normalize();
        assert!(
            (n - want).length() < 1e-6,
            "expected {want}, got {n}, tolerance 1e-6"
        );
    }

    /// Standard base64 (RFC 4648) for the test fixture.
    fn base64_encode(data: &[u8]) -> String {
        const T: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
        let mut s = String::new();
        for chunk in data.chunks(3) {
            let b = [
                chunk[0],
                *chunk.get(1).unwrap_or(&0),
                *chunk.get(2).unwrap_or(&0),
            ];
            let n = (b[0] as u32) << 16 | (b[1] as u32) << 8 | b[2] as u32;
            for k in 0..4 {
                if k <= chunk.len() {
                    s.push(T[(n >> (18 - 6 * k)) as usize & 63] as char);
                } else {
                    s.push('=');
                }
            }
        }
        s
    }

    #[test]
    fn gltf_embedded_triangle_is_placed_by_its_node() {
        let text = triangle_gltf([0.0, 0.0, -3.0]);
        let m = read_gltf_bytes(text.as_bytes(), "tri.gltf").unwrap();
        assert_eq!(m.len(), 1);
        assert_eq!(m[0].triangles, vec![[0, 1, 2]]);
        assert_eq!(m[0].positions[1], Vec3::new(1.0, 0.0, -3.0));
        assert!(m[0].uvs.is_none());
    }

    #[test]
    fn gltf_errors_name_the_source() {
        let e = read_gltf_bytes(b"{not json", "bad.gltf").unwrap_err();
        assert!(e.to_string().contains("bad.gltf"), "{e}");
        // An index past the vertex count is refused at the file boundary.
        let text = triangle_gltf([0.0; 3]).replace(
            "\"count\":3,\"type\":\"VEC3\"",
            "\"count\":2,\"type\":\"VEC3\"",
        );
        let e = read_gltf_bytes(text.as_bytes(), "short.gltf").unwrap_err();
        assert!(e.to_string().contains("short.gltf"), "{e}");
    }

    #[test]
    fn files_load_like_bytes() {
        // Write the fixtures to a private temporary directory, read them back by path.
        let dir = std::env::temp_dir().join(format!("texmap-mesh-read-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let obj = dir.join("quad.obj");
        std::fs::write(&obj, QUAD_OBJ).unwrap();
        let gltf = dir.join("tri.gltf");
        std::fs::write(&gltf, triangle_gltf([1.0, 2.0, 3.0])).unwrap();
        let a = read_obj(&obj).unwrap();
        let b = read_obj_bytes(QUAD_OBJ.as_bytes(), "quad.obj").unwrap();
        let c = read_gltf(&gltf).unwrap();
        std::fs::remove_dir_all(&dir).ok();
        assert_eq!(a, b);
        assert_eq!(c[0].positions[0], Vec3::new(1.0, 2.0, 3.0));
    }
}

/// The base colour of a glTF material (`pbrMetallicRoughness`): the linear RGBA factor and the
/// base-colour texture as 8-bit sRGB RGBA (when the material has one), with the index of the
/// texture-coordinate set it reads.
#[derive(Clone, Debug, PartialEq)]
pub struct BaseColor {
    pub factor: [f32; 4],
    pub texture: Option<image::RgbaImage>,
    pub tex_coord: u32,
}

/// The base colour of the first material a triangle primitive of `path` uses (meshes in file
/// order), `None` when no primitive has a material. Images embedded in a `.glb`, in data URIs
/// or in files beside a `.gltf` are decoded (PNG or JPEG); 16-bit and float images are refused.
pub fn read_gltf_base_color(path: impl AsRef<Path>) -> Result<Option<BaseColor>, MeshError> {
    let path = path.as_ref();
    let source = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|e| MeshError::Io {
        path: path.to_path_buf(),
        source: e,
    })?;
    let gerr = |message: String| MeshError::Gltf {
        source: source.clone(),
        message,
    };
    let gltf::Gltf { document, blob } =
        gltf::Gltf::from_slice(&bytes).map_err(|e| gerr(e.to_string()))?;
    let base = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let buffers =
        gltf::import_buffers(&document, Some(base), blob).map_err(|e| gerr(e.to_string()))?;
    let material = document
        .meshes()
        .flat_map(|m| m.primitives().collect::<Vec<_>>())
        .filter(|p| p.mode() == gltf::mesh::Mode::Triangles)
        .find_map(|p| p.material().index().map(|_| p.material()));
    let Some(material) = material else {
        return Ok(None);
    };
    let pbr = material.pbr_metallic_roughness();
    let factor = pbr.base_color_factor();
    let Some(info) = pbr.base_color_texture() else {
        return Ok(Some(BaseColor {
            factor,
            texture: None,
            tex_coord: 0,
        }));
    };
    let image = info.texture().source();
    let what = format!("image {}", image.index());
    if let gltf::image::Source::View { view, .. } = image.source() {
        // The decoder slices the buffer by the view without checking it.
        let len = buffers.get(view.buffer().index()).map_or(0, |b| b.0.len());
        if view
            .offset()
            .checked_add(view.length())
            .is_none_or(|end| end > len)
        {
            return Err(gerr(format!(
                "{what}: buffer view {} ends past its buffer ({len} bytes)",
                view.index()
            )));
        }
    }
    let data = gltf::image::Data::from_source(image.source(), Some(base), &buffers)
        .map_err(|e| gerr(format!("{what}: {e}")))?;
    let (w, h) = (data.width, data.height);
    let px = &data.pixels;
    use gltf::image::Format;
    let channels = match data.format {
        Format::R8 => 1,
        Format::R8G8 => 2,
        Format::R8G8B8 => 3,
        Format::R8G8B8A8 => 4,
        other => return Err(gerr(format!("{what}: pixel format {other:?} (need 8-bit)"))),
    };
    if px.len() != w as usize * h as usize * channels {
        return Err(gerr(format!(
            "{what}: {} bytes for {w} x {h} x {channels}",
            px.len()
        )));
    }
    let texture = image::RgbaImage::from_fn(w, h, |x, y| {
        let i = (y as usize * w as usize + x as usize) * channels;
        image::Rgba(match channels {
            1 => [px[i], px[i], px[i], 255],
            2 => [px[i], px[i], px[i], px[i + 1]],
            3 => [px[i], px[i + 1], px[i + 2], 255],
            _ => [px[i], px[i + 1], px[i + 2], px[i + 3]],
        })
    });
    Ok(Some(BaseColor {
        factor,
        texture: Some(texture),
        tex_coord: info.tex_coord(),
    }))
}
