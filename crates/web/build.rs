// The assets are compiled in: a change under assets/ rebuilds the crate.
fn main() {
    println!("cargo:rerun-if-changed=assets");
}
