#version 430
// Albedo pass, fragment stage: linear diffuse albedo (base color, per-vertex colors interpolated linearly,
// or the base-color texture decoded from sRGB by the sRGB8_ALPHA8 texture format and filtered bilinearly,
// as Mitsuba's bitmap texture does). Alpha-clipped materials (alpha_mode CLIP) drop fragments whose alpha
// (the alpha map, bilinear, or the constant) is below 0.5: the surface behind shows through.
uniform vec4 u_base_color;
uniform bool u_textured;
uniform bool u_vertex_colored;
uniform sampler2D u_texture;
uniform bool u_alpha_clip;
uniform bool u_alpha_mapped;
uniform float u_alpha;
uniform sampler2D u_alpha_texture;

in vec2 v_uv;
in vec3 v_color;

layout(location = 0) out vec4 out_albedo;

void main() {
    if (u_alpha_clip) {
        float alpha = u_alpha_mapped ? texture(u_alpha_texture, v_uv).r : u_alpha;
        if (alpha < 0.5) discard;
    }
    vec3 albedo = u_textured ? texture(u_texture, v_uv).rgb : (u_vertex_colored ? v_color : u_base_color.rgb);
    out_albedo = vec4(albedo, 1.0);
}
