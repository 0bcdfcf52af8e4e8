//! OBJ / PLY loading, including malformed files (errors must name the file, never panic).

use candela::geometry::{load_obj, load_ply, GeometryError, SceneGeometry, Shape};
use glam::Vec3;
use std::path::{Path, PathBuf};

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

const ASCII_PLY: &str = "ply
format ascii 1.0
comment a unit square (quad) plus a triangle
element vertex 5
property float x
property float y
property float z
property float nx
property float ny
property float nz
element face 2
property list uchar int vertex_indices
end_header
0 0 0 0 0 1
1 0 0 0 0 1
1 1 0 0 0 1
0 1 0 0 0 1
0 0 1 0 0 1
4 0 1 2 3
3 0 1 4
";

fn binary_ply(little: bool, truncate: usize) -> Vec<u8> {
    let fmt = if little {
        "binary_little_endian"
    } else {
        "binary_big_endian"
    };
    let mut b = format!(
        "ply\nformat {fmt} 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar uint vertex_indices\nend_header\n"
    )
    .into_bytes();
    let verts = [
        [0.0f32, 0.0, 0.0],
        [2.0, 0.0, 0.0],
        [2.0, 2.0, 0.0],
        [0.0, 2.0, 0.0],
    ];
    for v in verts {
        for c in v {
            b.extend(if little {
                c.to_le_bytes()
            } else {
                c.to_be_bytes()
            });
        }
    }
    b.push(4);
    for i in [0u32, 1, 2, 3] {
        b.extend(if little {
            i.to_le_bytes()
        } else {
            i.to_be_bytes()
        });
    }
    b.truncate(b.len() - truncate);
    b
}

#[test]
fn ply_ascii_and_binary() {
    let dir = tempfile::tempdir().unwrap();
    let m = load_ply(&write(dir.path(), "a.ply", ASCII_PLY.as_bytes())).unwrap();
    assert_eq!(m.positions.len(), 5);
    assert_eq!(m.indices, vec![[0, 1, 2], [0, 2, 3], [0, 1, 4]]);
    assert_eq!(m.normals.as_ref().unwrap()[4], Vec3::Z);
    for little in [true, false] {
        let m = load_ply(&write(dir.path(), "b.ply", &binary_ply(little, 0))).unwrap();
        assert_eq!(m.positions[2], Vec3::new(2.0, 2.0, 0.0));
        assert_eq!(m.indices, vec![[0, 1, 2], [0, 2, 3]]);
        assert!(m.normals.is_none());
        // It builds and renders: a ray through the middle hits at t = 1.
        let g = SceneGeometry::build(&[(Shape::Mesh(m), 0)]).unwrap();
        let h = g
            .intersect(Vec3::new(1.0, 1.0, 1.0), -Vec3::Z, f32::INFINITY)
            .unwrap();
        assert!((h.t - 1.0).abs() < 1e-6);
    }
}

#[test]
fn obj_quads_and_multiple_objects() {
    let dir = tempfile::tempdir().unwrap();
    let obj = "# two objects, a quad and a triangle (negative indices)
mtllib missing.mtl
o first
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
vn 0 0 1
f 1//1 2//1 3//1 4//1
o second
v 0 0 1
v 1 0 1
v 0 1 1
f -3 -2 -1
";
    let m = load_obj(&write(dir.path(), "m.obj", obj.as_bytes())).unwrap();
    assert_eq!(m.indices.len(), 3);
    // All indices valid and referring to the right positions.
    let tris: Vec<[Vec3; 3]> = m
        .indices
        .iter()
        .map(|t| t.map(|i| m.positions[i as usize]))
        .collect();
    assert!(tris.iter().any(|t| t.iter().all(|p| p.z == 1.0)));
    assert_eq!(
        tris.iter().filter(|t| t.iter().all(|p| p.z == 0.0)).count(),
        2
    );
    // Quad winding preserved: front faces point +Z.
    for t in &tris {
        assert!((t[1] - t[0]).cross(t[2] - t[0]).z > 0.0);
    }
}

fn expect_err(path: &Path, r: Result<candela::geometry::TriangleMesh, GeometryError>, what: &str) {
    match r {
        Ok(_) => panic!("{what}: expected an error"),
        Err(e) => {
            let msg = e.to_string();
            let name = path.file_name().unwrap().to_string_lossy().to_string();
            assert!(
                msg.contains(&name),
                "{what}: message does not name the file: {msg}"
            );
            println!("{what}: {msg}");
        }
    }
}

#[test]
fn malformed_files_give_errors() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // Missing files.
    let p = d.join("does_not_exist.ply");
    expect_err(&p, load_ply(&p), "missing ply");
    let p = d.join("does_not_exist.obj");
    expect_err(&p, load_obj(&p), "missing obj");
    // A directory.
    expect_err(d, load_ply(d), "directory");
    // Truncated binary PLY (payload cut) and truncated ascii PLY (missing lines).
    for cut in [1, 5, 20, 40] {
        let p = write(d, &format!("trunc{cut}.ply"), &binary_ply(true, cut));
        expect_err(&p, load_ply(&p), "truncated binary ply");
    }
    let lines: Vec<&str> = ASCII_PLY.lines().collect();
    let p = write(
        d,
        "trunc_ascii.ply",
        lines[..lines.len() - 2].join("\n").as_bytes(),
    );
    expect_err(&p, load_ply(&p), "truncated ascii ply");
    let p = write(
        d,
        "trunc_header.ply",
        b"ply\nformat ascii 1.0\nelement vertex 3\nproperty fl",
    );
    expect_err(&p, load_ply(&p), "truncated header");
    let p = write(d, "empty.ply", b"");
    expect_err(&p, load_ply(&p), "empty ply");
    let p = write(d, "garbage.ply", &[0xff, 0xfe, 0x00, 0x12, 0x34]);
    expect_err(&p, load_ply(&p), "garbage ply");
    // Index out of range.
    let bad = ASCII_PLY.replace("3 0 1 4", "3 0 1 9");
    let p = write(d, "range.ply", bad.as_bytes());
    expect_err(&p, load_ply(&p), "ply index out of range");
    let bad = ASCII_PLY.replace("3 0 1 4", "3 0 1 -1");
    let p = write(d, "negative.ply", bad.as_bytes());
    expect_err(&p, load_ply(&p), "ply negative index");
    let p = write(d, "range.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n");
    expect_err(&p, load_obj(&p), "obj index out of range");
    // Non-numeric.
    let bad = ASCII_PLY.replace("1 1 0 0 0 1", "1 abc 0 0 0 1");
    let p = write(d, "nonnum.ply", bad.as_bytes());
    expect_err(&p, load_ply(&p), "ply non-numeric");
    let p = write(d, "nonnum.obj", b"v 0 0 0\nv 1 x 0\nv 0 1 0\nf 1 2 3\n");
    expect_err(&p, load_obj(&p), "obj non-numeric vertex");
    let p = write(
        d,
        "nonnum_face.obj",
        b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 b 3\n",
    );
    expect_err(&p, load_obj(&p), "obj non-numeric face");
    // NaN coordinates.
    let bad = ASCII_PLY.replace("1 1 0 0 0 1", "1 nan 0 0 0 1");
    let p = write(d, "nan.ply", bad.as_bytes());
    expect_err(&p, load_ply(&p), "ply NaN");
    let p = write(d, "nan.obj", b"v 0 0 0\nv 1 NaN 0\nv 0 1 0\nf 1 2 3\n");
    expect_err(&p, load_obj(&p), "obj NaN");
    // No triangles.
    let p = write(d, "notris.obj", b"v 0 0 0\nv 1 0 0\n");
    expect_err(&p, load_obj(&p), "obj without faces");
    let p = write(
        d,
        "notris.ply",
        b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n",
    );
    expect_err(&p, load_ply(&p), "ply without faces");
    let p = write(d, "empty.obj", b"");
    expect_err(&p, load_obj(&p), "empty obj");
    // Missing x/y/z properties.
    let p = write(
        d,
        "noxyz.ply",
        b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float u\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0\n1\n2\n3 0 1 2\n",
    );
    expect_err(&p, load_ply(&p), "ply without xyz");
}
