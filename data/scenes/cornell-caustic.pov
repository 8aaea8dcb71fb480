// cornell-caustic.pov: cornell-caustic.scn translated for POV-Ray 3.7, the
// baseline scripts/bench-ref.sh times photosplat-ref against.
//
//   povray +Icornell-caustic.pov +Oout.png +W512 +H512 -D +A0.1 +AM2 +R3 \
//          File_Gamma=sRGB Declare=Exposure=0.3 [Declare=Photons=…] [Declare=RadCount=…]
//
// Values a command line may override with Declare=NAME=VALUE:
//   Exposure     radiance multiplier before sRGB encoding, as photosplat's --exposure (1)
//   Photons      caustic photons (POV's `photons { count }`) (200000, the .scn's default)
//   RadCount     radiosity rays per sample (200)
//   RadError     radiosity error_bound (0.5)
//   RadPretrace  radiosity pretrace_end (0.005)
//   RadBounces   radiosity recursion_limit (8: with 3 the indirect light of this
//                albedo-0.75 box comes out about 10% darker than photosplat-ref's,
//                with 8 about 3-5%)
//   RadNearest   radiosity nearest_count (10)
//   Radiosity    0: no radiosity, direct light and caustic photons only (1)
//
// Units are the .scn's: metres, and colours are radiance in W sr^-1 m^-2 (times
// Exposure), so the PNG is what photosplat-ref writes with the same --exposure.
//
// Coordinates: the .scn is right-handed (y up, camera at +z looking toward -z,
// +x to the right of the picture). POV-Ray is left-handed; `right -x` makes
// the camera right-handed too (POV's documented idiom for right-handed
// scenes), so every coordinate below is copied unchanged and the picture is
// not mirrored: the red wall (x = -1) is on the left.
#version 3.7;

#ifndef (Exposure)    #declare Exposure = 1; #end
#ifndef (Photons)     #declare Photons = 200000; #end
#ifndef (RadCount)    #declare RadCount = 200; #end
#ifndef (RadError)    #declare RadError = 0.5; #end
#ifndef (RadPretrace) #declare RadPretrace = 0.005; #end
#ifndef (RadBounces)  #declare RadBounces = 8; #end
#ifndef (RadNearest)  #declare RadNearest = 10; #end
#ifndef (Radiosity)   #declare Radiosity = 1; #end

global_settings {
    assumed_gamma 1.0           // linear arithmetic; File_Gamma=sRGB encodes the PNG
    ambient_light 0
    max_trace_level 16          // photosplat-ref: PS_RENDER_MAX_SPECULAR
    adc_bailout 0.001
    photons {
        count Photons
        autostop 0              // shoot the whole cone at each target
        jitter 0.4
        max_trace_level 16
        adc_bailout 0.001
    }
    #if (Radiosity)
    radiosity {
        pretrace_start 0.08
        pretrace_end RadPretrace
        count RadCount
        nearest_count RadNearest
        error_bound RadError
        recursion_limit RadBounces
        low_error_factor 0.5
        gray_threshold 0
        minimum_reuse 0.005
        brightness 1            // no artistic gain: physically the diffuse bounce
        adc_bailout 0.001
        normal off
        media off
        always_sample off
    }
    #end
}

// camera eye 0 1 3.4  target 0 1 0  up 0 1 0  fov 40 (vertical); image 512x512.
// POV's `angle` is the horizontal field of view: equal to the vertical one at
// aspect 1 (the bench renders square images only).
camera {
    perspective
    location <0, 1, 3.4>
    up y
    right -x                    // right-handed, see above; aspect 1
    angle 40
    look_at <0, 1, 0>
}

// light point position 0 1.9 0 power 100 100 100 (watts per channel).
// photosplat: intensity I = 100 / (4 pi) W/sr, and a diffuse surface of
// albedo a sends radiance L = a/pi * I cos / d^2.
// POV-Ray: L = a * diffuse * C * A(d) * cos with fade_power 2,
// A(d) = 2 / (1 + (d/D)^2) = 2 D^2 / (D^2 + d^2), and no 1/pi.
// Equal when C * 2 D^2 = I / pi = 100 / (4 pi^2) = 2.5330296, for d >> D.
// D = 1 mm (every surface is at least 0.1 m away: the error is < 1e-4), so
// C = 2.5330296 / (2e-6) = 1266514.8. POV-Ray's photons carry the same fade
// over their whole path length, and its radiosity gathers the cosine-weighted
// mean radiance (= E/pi), so caustics and indirect light share this scale.
#declare Fade = 0.001;
#declare LightC = 100 / (4 * pi * pi) / (2 * Fade * Fade);
light_source {
    <0, 1.9, 0>
    color rgb LightC * Exposure
    fade_distance Fade
    fade_power 2
    photons { refraction on reflection on }
}

// materials: diffuse `albedo` -> pigment, `diffuse 1 ambient 0` (and no
// highlights: photosplat's diffuse is pure Lambert).
#macro Diffuse(C)
    texture {
        pigment { rgb C }
        finish { ambient 0 emission 0 diffuse 1 specular 0 phong 0 reflection 0 }
    }
#end
#declare White = <0.75, 0.75, 0.75>;
#declare Red   = <0.75, 0.25, 0.25>;
#declare Green = <0.25, 0.75, 0.25>;

// dielectric ior 1.5: clear, Fresnel reflection, the rest transmitted.
#declare Glass = material {
    texture {
        pigment { rgbf <1, 1, 1, 1> }
        finish {
            ambient 0 emission 0 diffuse 0 specular 0 phong 0
            reflection { 0, 1 fresnel on }
            conserve_energy
        }
    }
    interior { ior 1.5 }
}
// mirror reflectance 1 1 1
#declare Mirror = texture {
    pigment { rgb 0 }
    finish { ambient 0 emission 0 diffuse 0 specular 0 phong 0 reflection { 1 } }
}

// quad corner C edge1 E1 edge2 E2: the parallelogram C, C+E1, C+E1+E2, C+E2.
#macro Quad(C, E1, E2, Col)
    polygon { 5, C, C + E1, C + E1 + E2, C + E2, C Diffuse(Col) }
#end

Quad(<-1, 0, -1>, <0, 0, 2>, <2, 0, 0>, White)   // floor
Quad(<-1, 2, -1>, <2, 0, 0>, <0, 0, 2>, White)   // ceiling
Quad(<-1, 0, -1>, <2, 0, 0>, <0, 2, 0>, White)   // back
Quad(<-1, 0, -1>, <0, 2, 0>, <0, 0, 2>, Red)     // left
Quad(< 1, 0, -1>, <0, 0, 2>, <0, 2, 0>, Green)   // right

sphere {
    <0.35, 0.4, 0.2>, 0.4
    material { Glass }
    photons { target refraction on reflection on collect off }
}
sphere {
    <-0.45, 0.35, -0.4>, 0.35
    texture { Mirror }
    photons { target reflection on collect off }
}
