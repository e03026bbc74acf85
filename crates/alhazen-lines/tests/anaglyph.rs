//! Red–cyan anaglyph line drawings from a stereo camera: each eye's visible and reflected lines
//! on its own coloured layer of one paper, the same lines as the side-by-side pair's halves.

use alhazen_lines::drawing::{Layer, default_stroke};
use alhazen_lines::{Options, draw};

const SCENE: &str = "[render]\nwidth = 400\nheight = 300\n[camera]\ntype = \"stereo\"\neye = [3.0, 2.5, 4.0]\n\
     target = [0, 0, 0]\n[[object]]\nshape = \"box\"\n[[object]]\nshape = \"sphere\"\ncenter = [2.2, 0, 0]\n\
     radius = 0.8\nmaterial = { mirror = 1 }\n";

#[test]
fn an_anaglyph_is_the_pair_overlaid_in_red_and_cyan() {
    let scene = alhazen_scene::parse_scene("stereo.toml".as_ref(), SCENE).unwrap();
    let (pair, _) = draw(&scene, &Options { hidden: true, ..Options::default() }).unwrap();
    let (glyph, stats) = draw(&scene, &Options { anaglyph: true, ..Options::default() }).unwrap();
    assert_eq!(glyph.size.x * 2.0, pair.size.x, "one eye's paper");
    assert_eq!(glyph.count(Layer::Hidden) + glyph.count(Layer::Visible) + glyph.count(Layer::Reflected), 0);
    assert!(glyph.count(Layer::Left) > 0 && glyph.count(Layer::Right) > 0, "{stats:?}");
    // The same lines as the pair's, visible and reflected, the right eye's moved onto the one
    // paper (each eye's part of the pair lies on its half).
    let shown = pair.length(Layer::Visible) + pair.length(Layer::Reflected);
    let overlaid = glyph.length(Layer::Left) + glyph.length(Layer::Right);
    assert!((overlaid - shown).abs() < 1e-9 * shown, "{overlaid} vs {shown}");
    let on_paper = |x: f64| (-1e-9..=glyph.size.x + 1e-9).contains(&x);
    assert!(glyph.lines.iter().all(|(_, p)| p.iter().all(|q| on_paper(q.x))));
    // Red and cyan ink on the preview, black where they cross.
    let (w, h, rgb) = glyph.to_pixels(400, default_stroke);
    let px = |k: usize| [rgb[3 * k], rgb[3 * k + 1], rgb[3 * k + 2]];
    let all: Vec<[u8; 3]> = (0..(w * h) as usize).map(px).collect();
    assert!(all.iter().any(|c| c[0] > 200 && c[1] < 60 && c[2] < 60), "red");
    assert!(all.iter().any(|c| c[0] < 60 && c[1] > 200 && c[2] > 200), "cyan");
}
