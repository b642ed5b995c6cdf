fn main() -> std::process::ExitCode {
    slosh_node::cli::main()
}
