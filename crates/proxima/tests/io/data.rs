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
    // The operating system's error is kept as the source.
    let e = load(path("no_such.obj")).unwrap_err();
    let src = std::error::Error::source(&e).expect("source");
    let io = src.downcast_ref::<std::io::Error>().expect("an io::Error");
    assert_eq!(io.kind(), std::io::ErrorKind::NotFound);
    assert!(e.to_string().contains("no_such.obj"), "{e}");
    assert_eq!(e, load(path("no_such.obj")).unwrap_err());
}

#[test]
fn unknown_format_has_its_own_error() {
    let file = std::env::temp_dir().join(format!("proxima-unknown-{}.xyz", std::process::id()));
    std::fs::write(&file, b"neither a mesh nor anything else\n").unwrap();
    let e = load(&file).unwrap_err();
    let _ = std::fs::remove_file(&file);
    match &e {
        proxima::Error::UnknownFormat { file: f } => assert!(f.ends_with(".xyz"), "{f}"),
        other => panic!("expected UnknownFormat, got {other:?}"),
    }
    assert!(e.to_string().contains("unknown mesh format"), "{e}");
    assert_eq!(e.to_string().lines().count(), 1);
}

#[test]
fn a_mesh_loads_with_its_trees_in_one_call() {
    use proxima::narrow::{Kdop18, Mesh, Obb};
    let m = Mesh::<Kdop18>::load(path("bunny.obj")).unwrap();
    assert_eq!(m.trimesh().len(), 3674);
    assert_eq!(m.trimesh(), &load(path("bunny.obj")).unwrap());
    m.bvh().validate(m.trimesh()).unwrap();
    let m = Mesh::<Obb>::load(path("forearm.stl")).unwrap();
    assert_eq!(m.trimesh().len(), 1000);
    assert!(matches!(
        Mesh::<Kdop18>::load(path("no_such.obj")),
        Err(proxima::Error::Io { .. })
    ));
}
