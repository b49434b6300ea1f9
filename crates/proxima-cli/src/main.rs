fn main() {
    eprintln!("proxima: no command yet");
    std::process::exit(2);
}
