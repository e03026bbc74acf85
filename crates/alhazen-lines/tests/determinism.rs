//! A drawing is a pure function of the scene and the options: the same bytes at any thread count.

use alhazen_lines::drawing::default_stroke;
use alhazen_lines::{Options, draw};
use std::path::Path;

#[test]
fn the_svg_is_identical_on_one_and_on_three_threads() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/lines/fig1-town-in-cylinder.toml");
    let scene = alhazen_scene::load_scene(&path).unwrap();
    let svg = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| draw(&scene, &Options { hidden: true, ..Options::default() }).unwrap().0.to_svg(default_stroke))
    };
    let one = svg(1);
    assert!(one.len() > 10_000);
    assert_eq!(one, svg(3));
}
