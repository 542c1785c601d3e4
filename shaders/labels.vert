#version 430
// Label pass, vertex stage. Positions are in the object's local frame (metres).
// u_modelview maps local -> OpenCV camera coordinates (x right, y down, z forward).
// Flat-shaded meshes are uploaded with one vertex per face corner carrying the exact face normal, so every
// mesh is drawn the same way (gl_PrimitiveID, the alternative, halves llvmpipe's throughput).
// UVs are bound only for alpha cut-outs (render/alpha_cutout.py).
uniform mat4 u_modelview;
uniform mat4 u_projection;      // pixel-centre projection built from K (see hybridgen/render/projection.py)
uniform mat3 u_normal_to_cam;   // inverse-transpose of the local -> camera linear part

in vec3 in_position;
in vec3 in_normal;
in vec2 in_uv;

out float v_z;                  // camera z (m)
out vec3 v_cam_normal;
out vec2 v_uv;

void main() {
    vec4 p = u_modelview * vec4(in_position, 1.0);
    v_z = p.z;
    v_cam_normal = u_normal_to_cam * in_normal;
    v_uv = in_uv;
    gl_Position = u_projection * p;
}
