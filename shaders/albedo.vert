#version 430
// Albedo pass, vertex stage: positions in the object's local frame, UVs as stored in the mesh (v up),
// per-vertex linear colors where the material takes its base color from them.
uniform mat4 u_modelview;
uniform mat4 u_projection;

in vec3 in_position;
in vec2 in_uv;
in vec3 in_color;

out vec2 v_uv;
out vec3 v_color;

void main() {
    v_uv = in_uv;
    v_color = in_color;
    gl_Position = u_projection * (u_modelview * vec4(in_position, 1.0));
}
