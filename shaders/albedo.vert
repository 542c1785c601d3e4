#version 430
// Albedo pass, vertex stage: positions in the object's local frame, UVs as stored in the mesh (v up),
// per-vertex linear colors where the material takes its base color from them; for dust films (dust.glsl) the
// world position and normal (u_model, its inverse transpose u_normal_matrix).
uniform mat4 u_modelview;
uniform mat4 u_projection;
uniform mat4 u_model;
uniform mat3 u_normal_matrix;

in vec3 in_position;
in vec2 in_uv;
in vec3 in_color;
in vec3 in_normal;

out vec2 v_uv;
out vec3 v_color;
out vec3 v_world;
out vec3 v_normal;

void main() {
    v_uv = in_uv;
    v_color = in_color;
    v_world = (u_model * vec4(in_position, 1.0)).xyz;
    v_normal = u_normal_matrix * in_normal;
    gl_Position = u_projection * (u_modelview * vec4(in_position, 1.0));
}
