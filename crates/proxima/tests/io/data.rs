//! Every mesh in shared/data loads with the counts of its README.

use proxima::io::{load, parse, Format};

fn path(name: &str) -> String {
    concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data/").to_string() + name
}

#[test]
fn shared_meshes_load_with_documented_counts() {
    for (name, tris) in [
        ("env.obj", 2180),
        ("rob.obj", 216),
        ("bunny.obj", 3674),
        ("teapot.obj", 992),
        ("SKINbody.stl", 33900),
        ("BONERibcage.stl", 73960),
        ("forearm.stl", 1000),
        ("hand_3finger.stl", 1000),
    ] {
        let mesh = load(path(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(mesh.len(), tris, "{name}");
    }
    assert_eq!(load(path("bunny.obj")).unwrap().vertices().len(), 1839);
    // FCL's soups: 3 vertices per triangle, as the header says.
    assert_eq!(load(path("env.obj")).unwrap().vertices().len(), 6540);
}

#[test]
fn binary_stl_welds_to_a_closed_surface() {
    // STL stores 3 corners per triangle; welding shares them (a closed surface
    // has about half as many vertices as triangles).
    for name in ["forearm.stl", "SKINbody.stl"] {
        let mesh = load(path(name)).unwrap();
        assert!(
            mesh.vertices().len() <= mesh.len() / 2 + 2,
            "{name}: {}",
            mesh.vertices().len()
        );
    }
}

#[test]
fn content_sniffing_matches_extension() {
    for (name, f) in [("bunny.obj", Format::Obj), ("forearm.stl", Format::Stl)] {
        let bytes = std::fs::read(path(name)).unwrap();
        assert_eq!(Format::sniff(&bytes), Some(f));
        assert_eq!(
            parse(name, &bytes, f).unwrap().len(),
            load(path(name)).unwrap().len()
        );
    }
}

#[test]
fn missing_file_is_an_io_error() {
    assert!(matches!(
        load(path("no_such.obj")),
        Err(proxima::Error::Io { .. })
    ));
}
