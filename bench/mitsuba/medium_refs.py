#!/usr/bin/env python3
"""A test scene of tinted glass — dielectrics whose insides absorb (Beer–Lambert) — and its
Mitsuba 3 reference (`volpath`: Mitsuba's `path` integrator ignores media), for
crates/alhazen-import/tests/mitsuba.rs:

- absorbing-glass: a glass sphere filled with a homogeneous medium of albedo 0 (absorption
  only) declared in the shape, and a glass cube referring to one declared apart (with a
  `scale`; both media's `sigma_t` are `constvolume`s, as Mitsuba's RGB modes take a colour
  above 1 no other way), the cube held a little above a diffuse floor (a face on the floor
  would make the nearest hit there ambiguous), under a small light and a grey sky. The
  camera sees the sky, the floor and the light through both, each colour darkened by the
  length of glass crossed (test `absorbing_glass_agrees_with_mitsuba`).

    python3 bench/mitsuba/medium_refs.py [--spp 16384]

Writes absorbing-glass.xml and absorbing-glass-mitsuba.exr into
crates/alhazen-import/tests/data/mitsuba/.
"""
import argparse
from texture_refs import head, write_reference

SCENE = head("Tinted glass: dielectrics filled with absorbing media", 16, 45, "0, 1.4, 4.2", "0, 0.35, 0",
             integrator="volpath", script="medium_refs.py") + """    <medium type="homogeneous" id="amber">
        <volume name="sigma_t" type="constvolume"><rgb name="value" value="0.4, 1.2, 3.0"/></volume>
        <float name="scale" value="1.5"/>
        <float name="albedo" value="0"/>
    </medium>
    <shape type="rectangle">
        <transform name="to_world">
            <scale x="0.6" y="0.6" z="1"/>
            <rotate x="1" angle="90"/>
            <translate x="0.3" y="2.8" z="0.8"/>
        </transform>
        <emitter type="area"><rgb name="radiance" value="14, 13, 12"/></emitter>
    </shape>
    <emitter type="constant"><rgb name="radiance" value="0.5, 0.55, 0.6"/></emitter>
    <shape type="rectangle">
        <transform name="to_world">
            <scale value="3"/>
            <rotate x="1" angle="-90"/>
        </transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.7, 0.7, 0.7"/></bsdf>
    </shape>
    <shape type="sphere">
        <point name="center" value="-0.6, 0.55, 0"/>
        <float name="radius" value="0.55"/>
        <bsdf type="dielectric"><float name="int_ior" value="1.5"/></bsdf>
        <medium type="homogeneous" name="interior">
            <volume name="sigma_t" type="constvolume"><rgb name="value" value="2.5, 0.8, 0.3"/></volume>
            <float name="albedo" value="0"/>
        </medium>
    </shape>
    <shape type="cube">
        <transform name="to_world">
            <scale value="0.4"/>
            <rotate y="1" angle="30"/>
            <translate x="0.7" y="0.45" z="0.1"/>
        </transform>
        <bsdf type="dielectric"><float name="int_ior" value="1.5"/></bsdf>
        <ref name="interior" id="amber"/>
    </shape>
</scene>
"""


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--spp", type=int, default=16384)
    write_reference("absorbing-glass", SCENE, ap.parse_args().spp, seed=13)


if __name__ == "__main__":
    main()
