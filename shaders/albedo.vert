#version 430
// Albedo pass, vertex stage: positions in the object's local frame, UVs as stored in the mesh (v up).
uniform mat4 u_modelview;
uniform mat4 u_projection;

in vec3 in_position;
in vec2 in_uv;

out vec2 v_uv;

void main() {
    v_uv = in_uv;
    gl_Position = u_projection * (u_modelview * vec4(in_position, 1.0));
}
