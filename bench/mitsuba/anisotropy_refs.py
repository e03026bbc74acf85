#!/usr/bin/env python3
"""A test scene of brushed metal — Mitsuba's `principled` with `anisotropic` — and its Mitsuba 3
reference, for crates/alhazen-import/tests/mitsuba.rs:

- brushed-principled: three gold spheres of roughness 0.4 under a directional light; the left
  one of anisotropic 0.9, the middle one the same turned a quarter about x (its poles, and so
  its `∂p/∂u`, face the camera's up), the right one isotropic. Mitsuba stretches the facets to
  `α/a` along `∂p/∂u` and `α·a` across it (`a = √(1 − 0.9·anisotropic)`, Disney's); alhazen
  reads it as its metallic–roughness model with that stretch (test
  `principled_anisotropy_agrees_with_mitsuba`).

    python3 bench/mitsuba/anisotropy_refs.py [--spp 8192]

Writes brushed-principled.xml and brushed-principled-mitsuba.exr into
crates/alhazen-import/tests/data/mitsuba/.
"""
import argparse
from texture_refs import head, write_reference


def sphere(x, anisotropic, turned=False):
    turn = '<transform name="to_world"><rotate x="1" angle="90"/></transform>\n        ' if turned else ""
    return f"""    <shape type="sphere">
        <point name="center" value="{x}, 0, 0"/><float name="radius" value="0.45"/>
        {turn}<bsdf type="principled">
            <rgb name="base_color" value="1, 0.78, 0.34"/><float name="metallic" value="1"/>
            <float name="roughness" value="0.4"/><float name="anisotropic" value="{anisotropic}"/>
        </bsdf>
    </shape>
"""


SCENE = head("Brushed metal: principled spheres with anisotropic facets", 4, 40, "0, 0, 4", "0, 0, 0",
             size=(96, 32), script="anisotropy_refs.py") + """    <emitter type="directional">
        <vector name="direction" value="-0.4, -0.6, -1"/><rgb name="irradiance" value="4"/>
    </emitter>
""" + sphere(-1, 0.9) + sphere(0, 0.9, turned=True) + sphere(1, 0.0) + "</scene>\n"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--spp", type=int, default=8192)
    write_reference("brushed-principled", SCENE, ap.parse_args().spp, seed=17)


if __name__ == "__main__":
    main()
