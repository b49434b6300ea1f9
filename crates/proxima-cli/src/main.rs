mod collide;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.first().map(String::as_str) {
        Some("collide") => std::process::exit(collide::main(&args[1..])),
        _ => {
            eprintln!("proxima: no command yet");
            std::process::exit(2);
        }
    }
}
