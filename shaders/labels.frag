#version 430
// Label pass, fragment stage: one multiple-render-target write per pixel centre.
// Default targets:
//   location 0 (RGBA32F): unit normal (xyz, camera or world axes) and z-depth (w, metres along camera z)
//   location 1 (R32UI):   instance id (1..N; the cleared value 0 is the background)
// Packed targets (PACKED_TARGETS defined, hybridgen/render/label_targets.py): each label in its stored form -
//   location 0 (R32F): z-depth (metres; the host clears it to the depth background)
//   LOCATION_NORMAL_CODES (RG16UI, OCTAHEDRAL_NORMALS): octahedral code of the normal (as encode_octahedral)
//   LOCATION_INSTANCE (R8UI/R16UI/R32UI): instance id;  LOCATION_CATEGORY (CATEGORY_TARGET): category id
// Normals are turned to face the camera: the host sets the front-face winding per object so that
// gl_FrontFacing is true exactly when the side the geometric normal points to faces the camera.
uniform mat3 u_cam_to_output;   // identity for camera-axes normals, cam2world rotation for world axes
uniform uint u_instance_id;
#ifdef CATEGORY_TARGET
uniform uint u_category_id;
#endif
#ifdef ALPHA_CUTOUT  // the cut-out variant (render/alpha_cutout.py): drop fragments of alpha < 0.5
uniform bool u_alpha_mapped;
uniform float u_alpha;
uniform sampler2D u_alpha_texture;
#endif

in float v_z;
in vec3 v_cam_normal;
#ifdef ALPHA_CUTOUT
in vec2 v_uv;
#endif

#ifdef EXACT_DEPTH
// Hardware rasterizers interpolate from vertex positions snapped to their sub-pixel grid; this intersects the
// pixel centre's ray with the triangle's plane instead (render/face_planes.py).
layout(std430, binding = 0) readonly buffer FacePlanes { vec4 face_planes[]; };  // (n, w) local: n . x = w
uniform mat4 u_modelview;       // local -> camera (the vertex stage's)
uniform mat3 u_normal_to_cam;   // its linear part's inverse-transpose
uniform vec4 u_pixel_to_ray;    // (1/fx, 1/fy, -cx/fx, -cy/fy)
// EXACT_DEPTH_AGREEMENT is defined by the host with EXACT_DEPTH (render/face_planes.py: AGREEMENT)
flat in uint v_triangle_base;

float fragment_z() {
    vec4 plane = face_planes[v_triangle_base + uint(gl_PrimitiveID)];
    vec3 n = u_normal_to_cam * plane.xyz;
    precise float w = plane.w + dot(n, u_modelview[3].xyz);
    vec2 pixel = gl_FragCoord.xy - 0.5;  // the pixel centre (u, v): no y flip (render/projection.py)
    vec3 ray = vec3(pixel * u_pixel_to_ray.xy + u_pixel_to_ray.zw, 1.0);
    precise float slope = dot(n, ray);
    if (slope == 0.0) return v_z;
    precise float z = w / slope;
    // Coverage comes from snapped positions: a pixel centre given to a triangle seen edge-on can lie past the
    // plane's horizon, where the division extrapolates. Keep the plane's z only beside the interpolated one
    // (a GPU's interpolation error measured up to 3e-4 of the depth).
    return (z > 0.0 && abs(z - v_z) <= EXACT_DEPTH_AGREEMENT * v_z) ? z : v_z;
}
#else
float fragment_z() { return v_z; }
#endif

#ifdef PACKED_TARGETS
layout(location = 0) out float out_depth;
#ifdef OCTAHEDRAL_NORMALS
layout(location = LOCATION_NORMAL_CODES) out uvec2 out_normal_code;
#endif
layout(location = LOCATION_INSTANCE) out uint out_instance;
#ifdef CATEGORY_TARGET
layout(location = LOCATION_CATEGORY) out uint out_category;
#endif
#else
layout(location = 0) out vec4 out_normal_depth;
layout(location = 1) out uint out_instance;
#endif

#ifdef OCTAHEDRAL_NORMALS
// copysign(magnitude, s) for magnitude >= 0, honouring the sign bit of s (-0.0 counts as negative, as numpy's)
float with_sign_of(float magnitude, float s) {
    return (floatBitsToUint(s) & 0x80000000u) != 0u ? -magnitude : magnitude;
}

// The octahedral code of a unit normal: the float32 operations of io/label_encoding.encode_octahedral in the
// same order (codes 1..65535 per axis; (0, 0) for the zero normal).
uvec2 octahedral_code(vec3 n) {
    precise float l1 = abs(n.x) + abs(n.y);
    l1 = l1 + abs(n.z);
    if (l1 == 0.0) return uvec2(0u);
    precise float inverse = 1.0 / l1;
    precise float px = n.x * inverse;
    precise float py = n.y * inverse;
    if (n.z < 0.0) {  // fold the lower hemisphere over the diagonals
        precise float fx = with_sign_of(1.0 - abs(py), px);
        precise float fy = with_sign_of(1.0 - abs(px), py);
        px = fx;
        py = fy;
    }
    precise vec2 scaled = (vec2(px, py) + 1.0) * 32767.0;
    return uvec2(roundEven(scaled)) + 1u;
}
#endif

void main() {
#ifdef ALPHA_CUTOUT
    if ((u_alpha_mapped ? texture(u_alpha_texture, v_uv).r : u_alpha) < 0.5) discard;
#endif
#if !defined(PACKED_TARGETS) || defined(OCTAHEDRAL_NORMALS)
    vec3 n = gl_FrontFacing ? v_cam_normal : -v_cam_normal;
    float len = length(n);
    n = len > 0.0 ? n / len : vec3(0.0);
    vec3 normal = u_cam_to_output * n;
#endif
#ifdef PACKED_TARGETS
    out_depth = fragment_z();
#ifdef OCTAHEDRAL_NORMALS
    out_normal_code = octahedral_code(normal);
#endif
#ifdef CATEGORY_TARGET
    out_category = u_category_id;
#endif
#else
    out_normal_depth = vec4(normal, fragment_z());
#endif
    out_instance = u_instance_id;
}
