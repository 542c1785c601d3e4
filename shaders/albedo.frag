#version 430
// Albedo pass, fragment stage: linear diffuse albedo (base color, per-vertex colors interpolated linearly,
// or the base-color texture decoded from sRGB by the sRGB8_ALPHA8 texture format and filtered bilinearly,
// as Mitsuba's bitmap texture does). Alpha-clipped materials (alpha_mode CLIP) drop fragments whose alpha
// (the alpha map, bilinear, or the constant) is below 0.5: the surface behind shows through. Dust films mix
// their colors in by their weights (dust.glsl, included below by the albedo pass with DUST_FILMS defined, in
// scenes that have dust: compiled in, llvmpipe ran its code in every fragment even with u_dust_count 0 - 0.14 of
// 0.21 s CPU per 1536 x 1536 draw of BlenderProc's basics/basic scene). The diffuse-color variant
// (PRINCIPLED_DIFFUSE defined, render/raster/principled_diffuse.py) shows Cycles' Diffuse Color pass instead of
// the base color: what the Principled BSDF's layers leave of it from the view direction. Infused images
// (color_layers.glsl, with COLOR_LAYERS defined in scenes that have them) blend over the base color first.
uniform vec4 u_base_color;
uniform bool u_textured;
uniform bool u_vertex_colored;
uniform sampler2D u_texture;
uniform bool u_alpha_clip;
uniform bool u_alpha_mapped;
uniform float u_alpha;
uniform sampler2D u_alpha_texture;
uniform vec3 u_camera;   // world position of the camera (dust's view direction)
uniform bool u_dust_uv;  // the mesh has UVs (else dust reads (0, 0), as Cycles a missing UV map)
uniform float u_weight;  // the material's share of the surface (1; a mixed material's weight, render/raster/albedo_pass.py)

in vec2 v_uv;
in vec3 v_color;
in vec3 v_world;
in vec3 v_normal;

#ifdef DUST_FILMS
// dust.glsl
#endif
#ifdef COLOR_LAYERS
// color_layers.glsl
uniform bool u_layer_uv;  // the mesh has UVs (else the layers read (0, 0), as Cycles a missing UV map)
#endif
#ifdef PRINCIPLED_DIFFUSE
// principled_diffuse.glsl
#endif

layout(location = 0) out vec4 out_albedo;

void main() {
    if (u_alpha_clip) {
        float alpha = u_alpha_mapped ? texture(u_alpha_texture, v_uv).r : u_alpha;
        if (alpha < 0.5) discard;
    }
    vec3 albedo = u_textured ? texture(u_texture, v_uv).rgb : (u_vertex_colored ? v_color : u_base_color.rgb);
#ifdef COLOR_LAYERS
    albedo = infused_color(albedo, u_layer_uv ? v_uv : vec2(0.0));
#endif
#ifdef PRINCIPLED_DIFFUSE
    albedo = principled_diffuse(albedo, v_uv, abs(dot(normalize(v_normal), normalize(u_camera - v_world))));
#endif
#ifdef DUST_FILMS
    if (u_dust_count > 0) {
        vec3 n = normalize(v_normal);
        vec3 to_camera = normalize(u_camera - v_world);
        float cosine = dot(n, to_camera);
        n = cosine < 0.0 ? -n : n;  // the normal facing the viewer, as Cycles turns it
        albedo = dust_albedo(albedo, u_dust_uv ? v_uv : vec2(0.0), n.z, abs(cosine));
    }
#endif
    out_albedo = vec4(albedo * u_weight, 1.0);
}
