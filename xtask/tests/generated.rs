//! The files generated from the parameter declarations are what `cargo xtask generate` writes.

use run_cli::declared::check_generated;

#[test]
fn generated_blocks_are_current() {
    let root = xtask::workspace_root();
    let mut stale = Vec::new();
    for b in xtask::generate::blocks() {
        let text = std::fs::read_to_string(root.join(b.file)).unwrap();
        if let Err(e) = check_generated(b.file, &text, b.name, b.comment, &b.text) {
            stale.push(e);
        }
    }
    assert!(stale.is_empty(), "{}", stale.join("\n"));
}
