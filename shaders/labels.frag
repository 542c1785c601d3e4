#version 430
// Label pass, fragment stage: one multiple-render-target write per pixel centre.
//   target 0 (RGBA32F): unit normal (xyz, camera or world axes) and z-depth (w, metres along camera z)
//   target 1 (R32UI):   instance id (1..N; the cleared value 0 is the background)
// Normals are turned to face the camera: the host sets the front-face winding per object so that
// gl_FrontFacing is true exactly when the side the geometric normal points to faces the camera.
uniform mat3 u_cam_to_output;   // identity for camera-axes normals, cam2world rotation for world axes
uniform uint u_instance_id;
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

layout(location = 0) out vec4 out_normal_depth;
layout(location = 1) out uint out_instance;

void main() {
#ifdef ALPHA_CUTOUT
    if ((u_alpha_mapped ? texture(u_alpha_texture, v_uv).r : u_alpha) < 0.5) discard;
#endif
    vec3 n = gl_FrontFacing ? v_cam_normal : -v_cam_normal;
    float len = length(n);
    n = len > 0.0 ? n / len : vec3(0.0);
    out_normal_depth = vec4(u_cam_to_output * n, v_z);
    out_instance = u_instance_id;
}
