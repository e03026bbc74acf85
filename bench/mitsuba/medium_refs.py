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

- transmittance-glass: the same room, its smooth glass sphere and rough glass cube (α 0.1)
  without media but with a coloured `specular_transmittance`, which tints the light at each
  crossing (test `transmittance_glass_agrees_with_mitsuba`).

    python3 bench/mitsuba/medium_refs.py [--spp 16384] [NAME…]

Writes NAME.xml and NAME-mitsuba.exr into crates/alhazen-import/tests/data/mitsuba/.
"""
import argparse
from texture_refs import head, write_reference

# The room both scenes stand in: a small light above, a grey sky, a diffuse floor.
ROOM = """    <shape type="rectangle">
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
"""

SCENE = head("Tinted glass: dielectrics filled with absorbing media", 16, 45, "0, 1.4, 4.2", "0, 0.35, 0",
             integrator="volpath", script="medium_refs.py") + """    <medium type="homogeneous" id="amber">
        <volume name="sigma_t" type="constvolume"><rgb name="value" value="0.4, 1.2, 3.0"/></volume>
        <float name="scale" value="1.5"/>
        <float name="albedo" value="0"/>
    </medium>
""" + ROOM + """    <shape type="sphere">
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


# The same room with glass that tints what it lets through at each crossing instead
# (`specular_transmittance`): a smooth sphere and a rough cube, no media.
TRANSMITTANCE = head("Tinted glass: dielectrics whose specular_transmittance is a colour", 16, 45, "0, 1.4, 4.2",
                     "0, 0.35, 0", script="medium_refs.py") + """""" + ROOM + """    <shape type="sphere">
        <point name="center" value="-0.6, 0.55, 0"/>
        <float name="radius" value="0.55"/>
        <bsdf type="dielectric">
            <float name="int_ior" value="1.5"/>
            <rgb name="specular_transmittance" value="0.95, 0.6, 0.3"/>
        </bsdf>
    </shape>
    <shape type="cube">
        <transform name="to_world">
            <scale value="0.4"/>
            <rotate y="1" angle="30"/>
            <translate x="0.7" y="0.45" z="0.1"/>
        </transform>
        <bsdf type="roughdielectric">
            <float name="int_ior" value="1.5"/>
            <float name="alpha" value="0.1"/>
            <rgb name="specular_transmittance" value="0.4, 0.75, 0.9"/>
        </bsdf>
    </shape>
</scene>
"""


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--spp", type=int, default=16384)
    ap.add_argument("names", nargs="*", default=["absorbing-glass", "transmittance-glass"])
    a = ap.parse_args()
    scenes = {"absorbing-glass": (SCENE, 13), "transmittance-glass": (TRANSMITTANCE, 17)}
    for name in a.names:
        scene, seed = scenes[name]
        write_reference(name, scene, a.spp, seed=seed)


if __name__ == "__main__":
    main()
