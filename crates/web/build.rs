//! Build script: the app's assets are embedded, so a change under assets/
//! rebuilds the crate.
fn main() {
    println!("cargo:rerun-if-changed=assets");
}
