#version 430
// Albedo pass, fragment stage: linear diffuse albedo (base color, or the base-color texture decoded from
// sRGB by the sRGB8_ALPHA8 texture format and filtered bilinearly, as Mitsuba's bitmap texture does).
uniform vec4 u_base_color;
uniform bool u_textured;
uniform sampler2D u_texture;

in vec2 v_uv;

layout(location = 0) out vec4 out_albedo;

void main() {
    out_albedo = u_textured ? vec4(texture(u_texture, v_uv).rgb, 1.0) : vec4(u_base_color.rgb, 1.0);
}
