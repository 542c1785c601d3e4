#version 430
// Label pass, fragment stage: one multiple-render-target write per pixel centre.
//   target 0 (RGBA32F): unit normal (xyz, camera or world axes) and z-depth (w, metres along camera z)
//   target 1 (R32UI):   instance id (1..N; the cleared value 0 is the background)
// Face normals come from a storage buffer indexed by gl_PrimitiveID, so flat-shaded meshes get their exact
// geometric normal. Normals are turned to face the camera using the geometric normal.
layout(std430, binding = 0) readonly buffer FaceNormals { float face_normals[]; };  // xyz per face, local frame

uniform mat3 u_normal_to_cam;
uniform mat3 u_cam_to_output;   // identity for camera-axes normals, cam2world rotation for world axes
uniform bool u_smooth;
uniform uint u_instance_id;

in vec3 v_cam_pos;
in vec3 v_cam_normal;

layout(location = 0) out vec4 out_normal_depth;
layout(location = 1) out uint out_instance;

void main() {
    int f = gl_PrimitiveID * 3;
    vec3 geometric = u_normal_to_cam * vec3(face_normals[f], face_normals[f + 1], face_normals[f + 2]);
    vec3 n = u_smooth ? v_cam_normal : geometric;
    if (dot(geometric, v_cam_pos) > 0.0) {
        n = -n;
    }
    float len = length(n);
    n = len > 0.0 ? n / len : vec3(0.0);
    out_normal_depth = vec4(u_cam_to_output * n, v_cam_pos.z);
    out_instance = u_instance_id;
}
