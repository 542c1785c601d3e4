// Images infused over the base color (hybridgen/scene/color_layer.py, BlenderProc's infuse_texture): per layer,
// innermost first, Blender's MixRGB node of the base color (Color1) and the layer's image (Color2, linear, bilinear,
// repeating, read at the UV times its uv scale, inverted on request) at the clamped factor - MIX or OVERLAY, per
// channel, as Cycles' svm_mix_blend / svm_mix_overlay.
const int COLOR_LAYER_COUNT = 4;
uniform int u_layer_count;                          // layers of this object (0: its base color as it is)
uniform vec4 u_layer[COLOR_LAYER_COUNT];            // factor (clamped), uv scale, overlay (0/1), invert (0/1)
uniform sampler2D u_layer_texture[COLOR_LAYER_COUNT];

vec3 infused_color(vec3 base, vec2 uv) {
    for (int i = 0; i < COLOR_LAYER_COUNT; ++i) {
        if (i >= u_layer_count) break;
        vec4 layer = u_layer[i];
        vec3 texel = texture(u_layer_texture[i], uv * layer.y).rgb;
        if (layer.w > 0.5) texel = vec3(1.0) - texel;
        float keep = 1.0 - layer.x;
        if (layer.z > 0.5) {
            vec3 low = base * (vec3(keep) + 2.0 * layer.x * texel);
            vec3 high = vec3(1.0) - (vec3(keep) + 2.0 * layer.x * (vec3(1.0) - texel)) * (vec3(1.0) - base);
            base = mix(high, low, lessThan(base, vec3(0.5)));  // per channel: low where base < 0.5
        } else {
            base = keep * base + layer.x * texel;
        }
    }
    return base;
}
