#version 430
// Label pass, vertex stage. Positions are in the object's local frame (metres).
// u_modelview maps local -> OpenCV camera coordinates (x right, y down, z forward).
// Flat-shaded meshes are uploaded with one vertex per face corner carrying the exact face normal, so every
// mesh is drawn the same way (gl_PrimitiveID, the alternative, halves llvmpipe's throughput).
// UVs exist only in the cut-out variant (ALPHA_CUTOUT defined, render/alpha_cutout.py): objects without a
// cut-out are drawn by a program that interpolates and tests nothing more.
uniform mat4 u_modelview;
uniform mat4 u_projection;      // pixel-centre projection built from K (see hybridgen/render/projection.py)
uniform mat3 u_normal_to_cam;   // inverse-transpose of the local -> camera linear part

in vec3 in_position;
in vec3 in_normal;
#ifdef ALPHA_CUTOUT
in vec2 in_uv;
#endif
#ifdef EXACT_DEPTH  // hardware rasterizers (render/face_planes.py): z from the triangle's plane
in uint in_triangle_base;       // per instance: the draw's first triangle (its command's base instance)
flat out uint v_triangle_base;
#endif

out float v_z;                  // camera z (m)
out vec3 v_cam_normal;
#ifdef ALPHA_CUTOUT
out vec2 v_uv;
#endif

void main() {
    vec4 p = u_modelview * vec4(in_position, 1.0);
    v_z = p.z;
    v_cam_normal = u_normal_to_cam * in_normal;
#ifdef ALPHA_CUTOUT
    v_uv = in_uv;
#endif
#ifdef EXACT_DEPTH
    v_triangle_base = in_triangle_base;
#endif
    gl_Position = u_projection * p;
}
