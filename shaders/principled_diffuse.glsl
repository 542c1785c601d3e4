// Cycles' Diffuse Color pass (DiffCol) of Blender 4.2's Principled BSDF per fragment: the weight of its diffuse
// closure plus the albedo of its sheen closure (Cycles counts sheen as a diffuse closure). The same steps and
// tables as hybridgen/render/pathtrace/principled_layers.py's layer weights (render/raster/principled_diffuse.py
// sets the inputs and prepends the table layout as #defines): each layer above the diffuse base takes its
// estimated albedo from the view direction - sheen (sheen weight x tint x R), coat (with Beer's-law tint), then
// (1 - metallic), (1 - transmission), the dielectric specular layer - and the base color is what is left.
layout(std430, binding = 3) readonly buffer PrincipledTables { float pd_table[]; };
uniform vec4 u_pd_surface;      // roughness, metallic, Specular IOR Level, IOR
uniform vec4 u_pd_layers;       // transmission, subsurface weight, coat weight, coat roughness
uniform vec4 u_pd_coat;         // coat IOR, coat tinted (0/1), sheen weight, sheen roughness
uniform vec3 u_pd_spec_tint;
uniform vec3 u_pd_coat_tint;
uniform vec3 u_pd_sheen_tint;
uniform bvec3 u_pd_mapped;      // roughness, metallic, Specular IOR Level read from their maps
uniform sampler2D u_pd_roughness_map;
uniform sampler2D u_pd_metallic_map;
uniform sampler2D u_pd_specular_map;

// Lower node, its weight's complement and the upper node's weight of v in 0..1 on n nodes (Dr.Jit's lookups).
void pd_coordinate(float v, int n, out int low, out float t) {
    float x = clamp(v, 0.0, 1.0) * float(n - 1);
    low = min(int(floor(x)), n - 2);
    t = x - float(low);
}

float pd_lookup_1d(int offset, int n, float x) {
    int i; float t;
    pd_coordinate(x, n, i, t);
    return mix(pd_table[offset + i], pd_table[offset + i + 1], t);
}

float pd_lookup_2d(int offset, int ny, int nx, float x, float y) {
    int ix, iy; float tx, ty;
    pd_coordinate(x, nx, ix, tx);
    pd_coordinate(y, ny, iy, ty);
    int row0 = offset + iy * nx + ix, row1 = row0 + nx;
    return mix(mix(pd_table[row0], pd_table[row0 + 1], tx), mix(pd_table[row1], pd_table[row1 + 1], tx), ty);
}

float pd_lookup_3d(int offset, int nz, int ny, int nx, float x, float y, float z) {
    int iz; float tz;
    pd_coordinate(z, nz, iz, tz);
    return mix(pd_lookup_2d(offset + iz * ny * nx, ny, nx, x, y),
               pd_lookup_2d(offset + (iz + 1) * ny * nx, ny, nx, x, y), tz);
}

float pd_f0(float eta) { float r = (eta - 1.0) / (eta + 1.0); return r * r; }

float pd_ior_from_f0(float f0) { float root = sqrt(clamp(f0, 0.0, 0.99)); return (1.0 + root) / (1.0 - root); }

float pd_max(vec3 c) { return max(max(c.r, c.g), c.b); }

// Estimated albedo of an energy-compensated dielectric GGX reflection whose Fresnel goes from f0 to 1 at
// relative IOR eta (principled_layers._reflective_layer).
vec3 pd_reflective_albedo(float rough, float mu, float eta, vec3 f0) {
    float e = max(pd_lookup_2d(PD_GGX_E, PD_GGX_E_SHAPE, rough, mu), 1e-4);
    float e_avg = pd_lookup_1d(PD_GGX_EAVG, PD_GGX_EAVG_SHAPE, rough);
    float z = sqrt(abs(eta - 1.0) / (eta + 1.0));
    float real_f0 = pd_f0(eta);
    float s_avg = clamp((pd_lookup_1d(PD_FRESNEL_AVG, PD_FRESNEL_AVG_SHAPE, z) - real_f0) / max(1.0 - real_f0, 1e-6),
                        0.0, 1.0);
    vec3 f_ss = mix(f0, vec3(1.0), s_avg);
    vec3 f_ms = f_ss * e_avg / max(1.0 - f_ss * (1.0 - e_avg), vec3(1e-6));
    vec3 factor = 1.0 + f_ms * (1.0 - e) / e;
    float s = pd_lookup_3d(PD_SCHLICK_S, PD_SCHLICK_S_SHAPE, rough, mu, z);
    return factor * e * mix(f0, vec3(1.0), s);
}

// DiffCol of the Principled BSDF with base color `base` seen at view cosine `mu` (to the shading normal).
vec3 principled_diffuse(vec3 base, vec2 uv, float mu) {
    mu = max(mu, 1e-6);
    float rough = clamp(u_pd_mapped.x ? texture(u_pd_roughness_map, uv).r : u_pd_surface.x, 0.0, 1.0);
    float metallic = clamp(u_pd_mapped.y ? texture(u_pd_metallic_map, uv).r : u_pd_surface.y, 0.0, 1.0);
    float level = max(u_pd_mapped.z ? texture(u_pd_specular_map, uv).r : u_pd_surface.z, 0.0);
    float ior = u_pd_surface.w;
    vec3 weight = vec3(1.0);
    vec3 sheen = vec3(0.0);
    if (u_pd_coat.z > 0.0) {
        sheen = u_pd_coat.z * u_pd_sheen_tint * pd_lookup_2d(PD_SHEEN_R, PD_SHEEN_R_SHAPE, u_pd_coat.w, mu);
        weight *= clamp(1.0 - pd_max(sheen), 0.0, 1.0);
    }
    float coat = u_pd_layers.z;
    if (coat > 0.0) {
        float coat_ior = u_pd_coat.x;
        vec3 albedo = pd_reflective_albedo(u_pd_layers.w, mu, coat_ior, vec3(pd_f0(coat_ior)));
        weight *= clamp(1.0 - coat * pd_max(albedo), 0.0, 1.0);
        if (u_pd_coat.y > 0.0) {
            float cos_t = sqrt(max(1.0 - (1.0 - mu * mu) / (coat_ior * coat_ior), 0.0));
            weight *= mix(vec3(1.0), pow(u_pd_coat_tint, vec3(1.0 / max(cos_t, 1e-4))), coat);
        }
    }
    weight *= (1.0 - metallic) * (1.0 - u_pd_layers.x);
    float real_f0 = pd_f0(ior);
    float eta = level == 0.5 ? ior : pd_ior_from_f0(real_f0 * 2.0 * level);
    if (ior < 1.0 && level != 0.5) eta = 1.0 / eta;
    if (abs(eta - 1.0) > 1e-6) {
        vec3 f0 = clamp(pd_f0(eta) * u_pd_spec_tint, 0.0, 1.0);
        weight *= clamp(1.0 - pd_max(pd_reflective_albedo(rough, mu, eta, f0)), 0.0, 1.0);
    }
    vec3 diffuse = mix(max(base, 0.0), clamp(base, 0.0, 1.0), u_pd_layers.y);
    return weight * diffuse + sheen;
}
