// POV-Ray 3.7 version of scenes/glass-balls.toml, for the timing comparison in BENCHMARKS.md.
// POV-Ray is left-handed; `right -x*4/3` mirrors the image so it matches alhazen's
// right-handed view.
#version 3.7;
global_settings { assumed_gamma 1.0 max_trace_level 8 ambient_light 0 }
camera { perspective location <0, 2.2, -7> look_at <0, 0.8, 0> right -x*4/3 angle 50 }
background { rgb <0.2, 0.3, 0.5> }
light_source { <-4, 8, -6> rgb 1 }
light_source { <5, 6, -3> rgb 0.6 }
plane { y, 0 pigment { checker rgb 0.9, rgb 0.15 } finish { diffuse 0.8 ambient 0 } }
#declare Glass = material { texture { pigment { rgbf <1, 1, 1, 1> } finish { ambient 0 diffuse 0 phong 1 phong_size 200 reflection { 0, 1 fresnel on } conserve_energy } } interior { ior 1.5 } }
#declare Water = material { texture { pigment { rgbf <1, 1, 1, 1> } finish { ambient 0 diffuse 0 phong 1 phong_size 200 reflection { 0, 1 fresnel on } conserve_energy } } interior { ior 1.33 } }
sphere { <-1.6, 1, 0.5>, 1 material { Glass } }
sphere { <0.9, 0.8, 1.2>, 0.8 pigment { rgb 0 } finish { ambient 0 diffuse 0 phong 1 phong_size 400 reflection 0.9 } }
cylinder { <2.6, 0, 2.5>, <2.6, 2.5, 2.5>, 0.6 pigment { rgb 0 } finish { ambient 0 diffuse 0 phong 1 phong_size 400 reflection 0.85 } }
sphere { <0.1, 0.45, -1.2>, 0.45 pigment { rgb <0.8, 0.1, 0.08> } finish { ambient 0 diffuse 1 phong 0.6 phong_size 60 } }
sphere { <-0.4, 0.35, -2.4>, 0.35 material { Water } }
