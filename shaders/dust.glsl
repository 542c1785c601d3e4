// Dust films in the albedo pass: hybridgen.scene.dust's weight per fragment, in GLSL (the same steps and
// constants as hybridgen/scene/dust.py and hybridgen/scene/gradient_noise.py: Blender's Noise Texture - Perlin
// noise with lookup3's final hash - at scale 250, detail 0, distortion 1.9, its 256-entry ramp 0.4 -> 0.46, the
// facing term, gamma 2.2, overlay, strength, clamp). Layers nest innermost first.
const int DUST_LAYERS = 4;
uniform int u_dust_count;                  // active layers (0: no dust, nothing below runs)
uniform vec4 u_dust[DUST_LAYERS];          // strength, texture scale, textured (0/1), unused
uniform vec3 u_dust_color[DUST_LAYERS];    // linear RGB of each layer's dust
uniform vec3 u_dust_offset[3];             // Blender's per-axis distortion offsets (random_offset(0, 1, 2))
uniform sampler2D u_dust_texture[DUST_LAYERS];

uint dust_rot(uint x, uint k) { return (x << k) | (x >> (32u - k)); }

uint dust_hash(uint kx, uint ky, uint kz) {
    uint a = kx + 0xDEADBF08u, b = ky + 0xDEADBF08u, c = kz + 0xDEADBF08u;
    c ^= b; c -= dust_rot(b, 14u);
    a ^= c; a -= dust_rot(c, 11u);
    b ^= a; b -= dust_rot(a, 25u);
    c ^= b; c -= dust_rot(b, 16u);
    a ^= c; a -= dust_rot(c, 4u);
    b ^= a; b -= dust_rot(a, 14u);
    c ^= b; c -= dust_rot(b, 24u);
    return c;
}

float dust_grad(uint hashed, vec3 p) {
    uint h = hashed & 15u;
    float u = h < 8u ? p.x : p.y;
    float vt = (h == 12u || h == 14u) ? p.x : p.z;
    float v = h < 4u ? p.y : vt;
    return ((h & 1u) != 0u ? -u : u) + ((h & 2u) != 0u ? -v : v);
}

vec3 dust_fade(vec3 t) { return t * t * t * (t * (t * 6.0 - 15.0) + 10.0); }

float dust_snoise(vec3 p) {
    p = p - 100000.0 * trunc(p * (1.0 / 100000.0));
    vec3 cell = floor(p);
    uvec3 i = uvec3(ivec3(cell));
    vec3 f = p - cell;
    vec3 w = dust_fade(f);
    float c000 = dust_grad(dust_hash(i.x, i.y, i.z), f);
    float c100 = dust_grad(dust_hash(i.x + 1u, i.y, i.z), f - vec3(1.0, 0.0, 0.0));
    float c010 = dust_grad(dust_hash(i.x, i.y + 1u, i.z), f - vec3(0.0, 1.0, 0.0));
    float c110 = dust_grad(dust_hash(i.x + 1u, i.y + 1u, i.z), f - vec3(1.0, 1.0, 0.0));
    float c001 = dust_grad(dust_hash(i.x, i.y, i.z + 1u), f - vec3(0.0, 0.0, 1.0));
    float c101 = dust_grad(dust_hash(i.x + 1u, i.y, i.z + 1u), f - vec3(1.0, 0.0, 1.0));
    float c011 = dust_grad(dust_hash(i.x, i.y + 1u, i.z + 1u), f - vec3(0.0, 1.0, 1.0));
    float c111 = dust_grad(dust_hash(i.x + 1u, i.y + 1u, i.z + 1u), f - vec3(1.0, 1.0, 1.0));
    float lower = (1.0 - w.y) * ((1.0 - w.x) * c000 + w.x * c100) + w.y * ((1.0 - w.x) * c010 + w.x * c110);
    float upper = (1.0 - w.y) * ((1.0 - w.x) * c001 + w.x * c101) + w.y * ((1.0 - w.x) * c011 + w.x * c111);
    return 0.982 * ((1.0 - w.z) * lower + w.z * upper);
}

float dust_ramp_stop(float i) { return clamp((0.46 - i * (1.0 / 255.0)) * (1.0 / 0.06), 0.0, 1.0); }

float dust_pattern(vec2 uv, float scale) {
    vec3 p = vec3(uv * (scale == 0.0 ? 0.0 : 1.0 / scale), 0.0) * 250.0;
    p += vec3(dust_snoise(p + u_dust_offset[0]), dust_snoise(p + u_dust_offset[1]),
              dust_snoise(p + u_dust_offset[2])) * 1.9;
    float value = 0.5 * dust_snoise(p) + 0.5;
    float position = clamp(value, 0.0, 1.0) * 255.0;
    float index = floor(position);
    float t = position - index;
    return (1.0 - t) * dust_ramp_stop(index) + t * dust_ramp_stop(clamp(index + 1.0, 0.0, 255.0));
}

vec3 dust_overlay(float g, vec3 pattern) {
    return g < 0.5 ? 2.0 * g * pattern : 1.0 - 2.0 * (1.0 - g) * (1.0 - pattern);
}

// The albedo under the dust layers: material share x albedo + each layer's share x its color.
vec3 dust_albedo(vec3 albedo, vec2 uv, float normal_z, float cos_view) {
    float mixed = 0.8 * clamp(normal_z, 0.0, 1.0) + 0.2 * (1.0 - abs(cos_view));
    float g = pow(clamp(mixed, 0.0, 1.0), 2.2);
    for (int k = 0; k < DUST_LAYERS; ++k) {
        if (k >= u_dust_count) break;
        vec4 layer = u_dust[k];
        float w;
        if (layer.z > 0.5) {
            vec2 at = uv * (layer.y == 0.0 ? 0.0 : 1.0 / layer.y);
            vec3 over = dust_overlay(g, texture(u_dust_texture[k], at).rgb);
            w = clamp(layer.x * dot(over, vec3(0.2126, 0.7152, 0.0722)), 0.0, 1.0);
        } else {
            w = clamp(layer.x * dust_overlay(g, vec3(dust_pattern(uv, layer.y))).x, 0.0, 1.0);
        }
        albedo = (1.0 - w) * albedo + w * u_dust_color[k];
    }
    return albedo;
}
