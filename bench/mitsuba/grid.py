#!/usr/bin/env python3
"""Scenes nobody tuned for. `grid` (the default): 49 objects on a floor — spheres, boxes and open cylinders (Mitsuba's
`cylinder`) of six materials, among them smooth gold/silver conductors (mirrors, so specular
connections), rough conductors, plastics, glass — under a 4×4 area lamp and a constant sky,
320×240, max depth 8. Written from a fixed seed, so every run renders the same file.

    python3 bench/mitsuba/grid.py [--scene grid|chrome-ball|gltf-metals|gltf-half-metals] [--spp 64] [--runs 3]

Two more are the suite's glossy scene changed as a user's would be: `chrome-ball` adds a small
smooth silver ball (a mirror: specular connections), `gltf-metals` writes its two rough metals
as Mitsuba's `principled` with metallic 1 (what a glTF metal becomes: alhazen reads it as the
glTF metallic-roughness model, a conductor with Schlick's Fresnel term; Mitsuba's principled
differs, so only the times compare); `gltf-half-metals` the same with metallic 0.5 (a
partly metallic glTF material: a mix of that conductor and Cook–Torrance).

Prints the whole `alhazen render` process's wall time (with and without specular connections)
and `mi.render`'s in Mitsuba `llvm_ad_rgb` (after a warm-up render), medians of the runs, and the
images' means. Needs `pip install mitsuba numpy`, `apt-get install libllvm19`; ALHAZEN=binary
(default target/release/alhazen).
"""
import argparse, os, random, subprocess, sys, tempfile, time

os.environ.setdefault("DRJIT_LIBLLVM_PATH", "/usr/lib/x86_64-linux-gnu/libLLVM-19.so")
import numpy as np
import mitsuba as mi

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import suite  # noqa: E402  (its `settle`: alhazen timed once Mitsuba is idle)

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
EXE = os.environ.get("ALHAZEN", os.path.join(ROOT, "target/release/alhazen"))
MATERIALS = [
    '<bsdf type="roughconductor"><string name="material" value="Au"/><float name="alpha" value="0.15"/></bsdf>',
    '<bsdf type="roughplastic"><rgb name="diffuse_reflectance" value="0.2,0.4,0.7"/><float name="alpha" value="0.1"/></bsdf>',
    '<bsdf type="dielectric"><float name="int_ior" value="1.5"/></bsdf>',
    '<bsdf type="diffuse"><rgb name="reflectance" value="0.7,0.3,0.2"/></bsdf>',
    '<bsdf type="roughdielectric"><float name="alpha" value="0.2"/></bsdf>',
    '<bsdf type="conductor"><string name="material" value="Ag"/></bsdf>',
]


def scene():
    rng = random.Random(3)
    shapes = []
    for i in range(7):
        for j in range(7):
            r = 0.25 + 0.1 * rng.random()
            x, z = (i - 3) * 1.0, (j - 3) * 1.0
            kind = rng.choice(["sphere", "sphere", "cube", "cylinder"])
            m = rng.choice(MATERIALS)
            if kind == "sphere":
                shapes.append(f'<shape type="sphere"><point name="center" x="{x}" y="{r}" z="{z}"/>'
                              f'<float name="radius" value="{r}"/>{m}</shape>')
            elif kind == "cube":
                shapes.append(f'<shape type="cube"><transform name="to_world"><scale value="{r}"/>'
                              f'<rotate y="1" angle="{rng.random() * 90}"/><translate x="{x}" y="{r}" z="{z}"/>'
                              f'</transform>{m}</shape>')
            else:
                shapes.append(f'<shape type="cylinder"><point name="p0" x="{x}" y="0" z="{z}"/>'
                              f'<point name="p1" x="{x}" y="{2 * r}" z="{z}"/><float name="radius" value="{r * 0.7}"/>'
                              f'{m}</shape>')
    body = "\n    ".join(shapes)
    return f'''<scene version="3.0.0">
    <integrator type="path"><integer name="max_depth" value="8"/></integrator>
    <sensor type="perspective">
        <float name="fov" value="45"/>
        <transform name="to_world"><lookat origin="0, 5, 9" target="0, 0, 0" up="0, 1, 0"/></transform>
        <sampler type="independent"><integer name="sample_count" value="64"/></sampler>
        <film type="hdrfilm"><integer name="width" value="320"/><integer name="height" value="240"/><rfilter type="box"/></film>
    </sensor>
    <shape type="rectangle"><transform name="to_world"><scale value="2"/><rotate x="1" angle="90"/><translate y="6"/></transform>
        <emitter type="area"><rgb name="radiance" value="6,6,6"/></emitter></shape>
    <emitter type="constant"><rgb name="radiance" value="0.3,0.35,0.4"/></emitter>
    <shape type="rectangle"><transform name="to_world"><scale value="10"/><rotate x="1" angle="-90"/></transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.5,0.5,0.5"/></bsdf></shape>
    {body}
</scene>
'''


def glossy_variant(name):
    """The suite's glossy scene as the variant `name` changes it."""
    with open(os.path.join(ROOT, "bench/mitsuba/suite/glossy.xml")) as f:
        text = f.read()
    if name == "chrome-ball":
        ball = ('<shape type="sphere"><point name="center" x="1.8" y="0.25" z="1.5"/>'
                '<float name="radius" value="0.25"/>'
                '<bsdf type="conductor"><string name="material" value="Ag"/></bsdf></shape>\n</scene>')
        return text.replace("</scene>", ball)
    for base, roughness in [("0.95, 0.64, 0.54", 0.3), ("0.91, 0.92, 0.92", 0.05)]:
        start = text.index('<bsdf type="roughconductor">')
        end = text.index("</bsdf>", start) + len("</bsdf>")
        metallic = 0.5 if name == "gltf-half-metals" else 1
        metal = (f'<bsdf type="principled"><rgb name="base_color" value="{base}"/>'
                 f'<float name="metallic" value="{metallic}"/><float name="roughness" value="{roughness}"/></bsdf>')
        text = text[:start] + metal + text[end:]
    return text


def mean(path):
    mi.set_variant("scalar_rgb")
    return float(np.array(mi.Bitmap(path))[..., :3].mean())


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--scene", choices=["grid", "chrome-ball", "gltf-metals", "gltf-half-metals"], default="grid")
    a = ap.parse_args()
    tmp = tempfile.mkdtemp()
    path = os.path.join(tmp, a.scene + ".xml")
    with open(path, "w") as f:
        f.write(scene() if a.scene == "grid" else glossy_variant(a.scene))
    mi.set_variant("llvm_ad_rgb")
    import drjit as dr
    loaded = mi.load_file(path)
    dr.eval(mi.render(loaded, spp=a.spp))

    def mitsuba():
        mi.set_variant("llvm_ad_rgb")
        t0 = time.perf_counter()
        img = mi.render(loaded, spp=a.spp, seed=1)
        dr.eval(img)
        pixels = np.array(img)  # waits for the render, as bench/mitsuba/suite.py does
        elapsed = time.perf_counter() - t0
        mi.Bitmap(pixels).write(os.path.join(tmp, "mitsuba.exr"))
        return elapsed

    def ours(*extra):
        out = os.path.join(tmp, "ours" + "".join(extra) + ".exr")
        suite.settle()
        t0 = time.perf_counter()
        subprocess.run([EXE, "render", path, "-o", out, "--spp", str(a.spp), "--quiet", *extra], check=True)
        return time.perf_counter() - t0, out

    rows = {"alhazen": [], "alhazen --no-mirror-connections": [], "Mitsuba llvm": []}
    for _ in range(a.runs):
        t, with_out = ours()
        rows["alhazen"].append(t)
        t, without_out = ours("--no-mirror-connections")
        rows["alhazen --no-mirror-connections"].append(t)
        rows["Mitsuba llvm"].append(mitsuba())
    means = [mean(with_out), mean(without_out), mean(os.path.join(tmp, "mitsuba.exr"))]
    print(f"{a.scene}: {os.cpu_count()} cores, {a.spp} spp, medians of {a.runs}")
    for (name, ts), m in zip(rows.items(), means):
        print(f"| {name} | {np.median(ts):.3f} s | mean {m:.5f} |")


if __name__ == "__main__":
    sys.exit(main())
