//! Writers (test-only, straightforward) for every supported encoding; a mesh
//! written and re-read must give the same triangles, corner by corner.

use glam::Vec3;
use proxima::io::{parse, Format};
use proxima::narrow::TriMesh;

fn sample() -> TriMesh {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/data/teapot.obj"
    );
    proxima::io::load(path).unwrap()
}

fn corners(m: &TriMesh) -> Vec<[Vec3; 3]> {
    (0..m.len()).map(|i| m.triangle(i)).collect()
}

fn stl_binary(m: &TriMesh, header: &[u8; 80]) -> Vec<u8> {
    let mut out = header.to_vec();
    out.extend((m.len() as u32).to_le_bytes());
    for t in corners(m) {
        out.extend([0u8; 12]);
        for p in t {
            for c in p.to_array() {
                out.extend(c.to_le_bytes());
            }
        }
        out.extend([0u8; 2]);
    }
    out
}

fn stl_ascii(m: &TriMesh) -> Vec<u8> {
    let mut s = String::from("solid teapot\n");
    for t in corners(m) {
        s += "  facet normal 0 0 1\n    outer loop\n";
        for p in t {
            s += &format!("      vertex {:e} {:e} {:e}\n", p.x, p.y, p.z);
        }
        s += "    endloop\n  endfacet\n";
    }
    s += "endsolid teapot\n";
    s.into_bytes()
}

/// PLY with distracting extras: a leading element, extra vertex properties of
/// several types, a face property before the index list, double coordinates.
fn ply(m: &TriMesh, format: &str) -> Vec<u8> {
    let mut out = format!(
        "ply\nformat {format} 1.0\ncomment made by the test\nelement junk 2\nproperty list uchar int stuff\n\
         element vertex {}\nproperty uchar red\nproperty double x\nproperty float y\nproperty double z\nproperty short s\n\
         element face {}\nproperty int flags\nproperty list uchar uint vertex_indices\nproperty list ushort char extra\nend_header\n",
        m.vertices().len(),
        m.len()
    )
    .into_bytes();
    let be = format == "binary_big_endian";
    let put = |out: &mut Vec<u8>, text: String, le: Vec<u8>| {
        if format == "ascii" {
            out.extend(text.bytes());
            out.push(b' ');
        } else if be {
            out.extend(le.iter().rev());
        } else {
            out.extend(le);
        }
    };
    for k in 0..2i32 {
        put(&mut out, "2".into(), vec![2]);
        put(&mut out, format!("{k}"), k.to_le_bytes().to_vec());
        put(&mut out, "-7".into(), (-7i32).to_le_bytes().to_vec());
    }
    for p in m.vertices() {
        put(&mut out, "255".into(), vec![255]);
        put(
            &mut out,
            format!("{}", p.x as f64),
            (p.x as f64).to_le_bytes().to_vec(),
        );
        put(&mut out, format!("{}", p.y), p.y.to_le_bytes().to_vec());
        put(
            &mut out,
            format!("{}", p.z as f64),
            (p.z as f64).to_le_bytes().to_vec(),
        );
        put(&mut out, "-3".into(), (-3i16).to_le_bytes().to_vec());
        if format == "ascii" {
            out.push(b'\n');
        }
    }
    for t in m.triangles() {
        put(&mut out, "9".into(), 9i32.to_le_bytes().to_vec());
        put(&mut out, "3".into(), vec![3]);
        for &i in t {
            put(&mut out, format!("{i}"), i.to_le_bytes().to_vec());
        }
        put(&mut out, "1".into(), 1u16.to_le_bytes().to_vec());
        put(&mut out, "-1".into(), vec![0xff]);
        if format == "ascii" {
            out.push(b'\n');
        }
    }
    out
}

#[test]
fn stl_round_trips() {
    let m = sample();
    let mut header = [b' '; 80];
    header[..10].copy_from_slice(b"solid fake"); // binary files may start with "solid"
    for (bytes, what) in [
        (stl_binary(&m, &header), "binary"),
        (stl_ascii(&m), "ascii"),
    ] {
        let back = parse("t.stl", &bytes, Format::Stl).unwrap_or_else(|e| panic!("{what}: {e}"));
        assert_eq!(corners(&back), corners(&m), "{what}");
        assert_eq!(Format::sniff(&bytes), Some(Format::Stl));
    }
}

#[test]
fn ply_round_trips() {
    let m = sample();
    for format in ["ascii", "binary_little_endian", "binary_big_endian"] {
        let bytes = ply(&m, format);
        let back = parse("t.ply", &bytes, Format::Ply).unwrap_or_else(|e| panic!("{format}: {e}"));
        assert_eq!(back, m, "{format}");
        assert_eq!(Format::sniff(&bytes), Some(Format::Ply));
    }
}

#[test]
fn obj_forms() {
    let text = "# comment\nmtllib x.mtl\no thing\nv 0 0 0\nv 1 0 0 1.0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n\
                g g1\nusemtl m\ns off\nf 1/1/1 2/1/1 3/1/1 4/1/1\nf -4//1 -3//1 -1//1 # relative\nf 1/1 3/1 4/1\n";
    let m = parse("t.obj", text.as_bytes(), Format::Obj).unwrap();
    assert_eq!(m.triangles(), &[[0, 1, 2], [0, 2, 3], [0, 1, 3], [0, 2, 3]]);
    assert_eq!(m.vertices()[1], Vec3::X);
    // CRLF line ends.
    let crlf = "v 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nf 1 2 3\r\n";
    assert_eq!(
        parse("t.obj", crlf.as_bytes(), Format::Obj).unwrap().len(),
        1
    );
    // The FCL header variant.
    let fcl = "3 1\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    assert_eq!(
        parse("t.obj", fcl.as_bytes(), Format::Obj).unwrap().len(),
        1
    );
}
