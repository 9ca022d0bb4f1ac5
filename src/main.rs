use clap::Parser;

fn main() -> std::process::ExitCode {
    rheosph::app::cli::main(rheosph::app::cli::Cli::parse())
}
