use clap::Parser;

fn main() -> std::process::ExitCode {
    rheosph::cli::main(rheosph::cli::Cli::parse())
}
