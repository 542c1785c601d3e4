#version 430
// Label pass, vertex stage. Positions are in the object's local frame (metres).
// u_modelview maps local -> OpenCV camera coordinates (x right, y down, z forward).
uniform mat4 u_modelview;
uniform mat4 u_projection;      // pixel-centre projection built from K (see hybridgen/render/projection.py)
uniform mat3 u_normal_to_cam;   // inverse-transpose of the local -> camera linear part
uniform bool u_smooth;          // true: interpolate vertex normals; false: exact face normals

in vec3 in_position;
in vec3 in_normal;

out vec3 v_cam_pos;
out vec3 v_cam_normal;

void main() {
    vec4 p = u_modelview * vec4(in_position, 1.0);
    v_cam_pos = p.xyz;
    v_cam_normal = u_smooth ? u_normal_to_cam * in_normal : vec3(0.0);
    gl_Position = u_projection * p;
}
