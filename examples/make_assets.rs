//! Regenerates the bundled assets in `assets/`: `cargo run --example make_assets`.

use std::path::Path;

use seethru::io::atomic::{write_atomically, write_text};
use seethru::scene::head_model::{head_mtl, head_obj};
use seethru::scene::procedural::{car_mtl, car_obj, street_texture};

fn main() -> anyhow::Result<()> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets");
    std::fs::create_dir_all(&dir)?;
    write_text(&dir.join("car.obj"), &car_obj())?;
    write_text(&dir.join("car.mtl"), &car_mtl())?;
    write_text(&dir.join("head.obj"), &head_obj())?;
    write_text(&dir.join("head.mtl"), &head_mtl())?;
    let street = street_texture();
    write_atomically(&dir.join("street.png"), |file| {
        Ok(street.write_to(file, image::ImageFormat::Png)?)
    })?;
    println!(
        "wrote car.obj, car.mtl, head.obj, head.mtl and street.png to {}",
        dir.display()
    );
    Ok(())
}
