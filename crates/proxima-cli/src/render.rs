//! `proxima render`: pictures without running the demo.
//!
//! ```text
//! proxima render TRACE [--out DIR] [--svg]
//! proxima render --collide A B [--pose R00 … R22 TX TY TZ | --poses FILE] [--out DIR] [--svg]
//! ```
//! With a trace [sources: trace-format]: the loose k-d tree's and the octree's partitions of
//! the objects alive at the end of the trace, as `proxima demo` draws them. With
//! `--collide`: the two meshes (the first one posed; a pose is 12 numbers, a
//! row-major rotation then a translation, as in pose files [sources: pose-format]; `--poses`
//! takes the first pose of a file), with the triangles that intersect in red.
//! Exit codes: 0 success, 2 bad input (one line naming the file and line).

use crate::draw::Canvas;
use crate::pictures;
use proxima::broad::SceneHint;
use proxima::geom::Sphere;
use proxima::glam::Affine3A;
use proxima::narrow::Mesh;
use proxima_harness::poses;
use proxima_harness::trace::{Op, Trace};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Options of `proxima render`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// A trace file: draw the partitions of the objects alive at its end.
    #[arg(required_unless_present = "collide", conflicts_with = "collide")]
    pub trace: Option<PathBuf>,
    /// Two mesh files (OBJ, STL, PLY): draw them and their intersecting triangles.
    #[arg(long, num_args = 2, value_names = ["A", "B"])]
    pub collide: Option<Vec<PathBuf>>,
    /// Pose of the first mesh: 12 numbers, row-major rotation then translation.
    #[arg(
        long,
        num_args = 12,
        allow_negative_numbers = true,
        value_name = "X",
        requires = "collide",
        conflicts_with = "poses"
    )]
    pub pose: Option<Vec<String>>,
    /// Take the pose of the first mesh from the first line of a pose file.
    #[arg(long, requires = "collide", value_name = "FILE")]
    pub poses: Option<PathBuf>,
    /// Directory for the pictures (created if missing).
    #[arg(long, default_value = "proxima-out", value_name = "DIR")]
    pub out: PathBuf,
    /// Write SVG instead of PNG.
    #[arg(long)]
    pub svg: bool,
}

/// Runs the command; returns the exit code.
pub fn main(args: &Args) -> ExitCode {
    let res = match (&args.collide, &args.trace) {
        (Some(files), _) => collide(args, files),
        (None, Some(trace)) => partitions(args, trace),
        (None, None) => Err("give a TRACE or --collide A B".to_string()),
    };
    match res {
        Ok(paths) => {
            for p in paths {
                println!("wrote {}", p.display());
            }
            ExitCode::SUCCESS
        }
        Err(msg) => {
            eprintln!("proxima render: {msg}");
            ExitCode::from(2)
        }
    }
}

fn save(args: &Args, c: &Canvas, stem: &str) -> Result<PathBuf, String> {
    std::fs::create_dir_all(&args.out)
        .map_err(|e| format!("cannot create {}: {e}", args.out.display()))?;
    let p = args
        .out
        .join(format!("{stem}.{}", if args.svg { "svg" } else { "png" }));
    c.save(&p)?;
    Ok(p)
}

fn stem(p: &Path) -> String {
    p.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".into())
}

/// The objects alive at the end of a trace, in slot order.
pub fn end_state(trace: &Trace) -> Vec<Sphere> {
    let mut live: Vec<Option<Sphere>> = vec![None; trace.ids.len()];
    for op in &trace.ops {
        match op {
            Op::Insert { slot, sphere } | Op::Move { slot, sphere } => {
                live[*slot as usize] = Some(*sphere)
            }
            Op::Remove { slot } => live[*slot as usize] = None,
            Op::Query(_) => {}
        }
    }
    live.into_iter().flatten().collect()
}

fn partitions(args: &Args, path: &Path) -> Result<Vec<PathBuf>, String> {
    let name = path.display();
    let text = std::fs::read(path).map_err(|e| format!("cannot read {name}: {e}"))?;
    let trace = Trace::parse(&text).map_err(|e| format!("{name}: {e}"))?;
    let spheres = end_state(&trace);
    let hint = SceneHint::from_spheres(spheres.iter().copied(), spheres.len());
    let s = stem(path);
    Ok(vec![
        save(
            args,
            &pictures::kd_partition(&spheres, &hint)?,
            &format!("{s}-loose-kd"),
        )?,
        save(
            args,
            &pictures::octree_partition(&spheres, &hint)?,
            &format!("{s}-octree"),
        )?,
    ])
}

fn collide(args: &Args, files: &[PathBuf]) -> Result<Vec<PathBuf>, String> {
    let load = |p: &PathBuf| {
        proxima::io::load(p).map_err(|e| {
            let s = e.to_string();
            let name = p.display().to_string();
            if s.contains(&name) {
                s
            } else {
                format!("{name}: {s}")
            }
        })
    };
    let (a, b) = (load(&files[0])?, load(&files[1])?);
    let pose = if let Some(nums) = &args.pose {
        poses::parse("--pose", &nums.join(" "))?[0]
    } else if let Some(p) = &args.poses {
        let text = std::fs::read_to_string(p).map_err(|e| format!("{}: {e}", p.display()))?;
        let name = p.display().to_string();
        *poses::parse(&name, &text)?
            .first()
            .ok_or_else(|| format!("{name}: no pose in the file"))?
    } else {
        Affine3A::IDENTITY
    };
    let opts = Default::default();
    let a: Mesh = Mesh::from_trimesh(a, opts).map_err(|e| e.to_string())?;
    let b: Mesh = Mesh::from_trimesh(b, opts).map_err(|e| e.to_string())?;
    let contacts = a.collide(&pose, &b).map_err(|e| e.to_string())?;
    println!("pairs {}", contacts.pairs.len());
    let (sa, sb) = (stem(&files[0]), stem(&files[1]));
    let c = pictures::meshes(
        &format!("{sa} (posed) vs {sb}: intersecting triangles"),
        a.trimesh(),
        &pose,
        b.trimesh(),
        &contacts.pairs,
    );
    Ok(vec![save(args, &c, &format!("collide-{sa}-{sb}"))?])
}
