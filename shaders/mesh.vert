#version 330 core
// Instanced meshes: the gravity-map arrows, the force arrow, the cursor and hand spheres.
// A mesh vertex is given in a local frame scaled by the instance: its radial part (x, y) and an
// axial offset z in units of the instance radius, plus an axial position a * length + b * head
// length along the instance direction. So one arrow mesh serves every length while the shaft
// thickness and head size stay constant on screen.
#include "colormap.glsl"

layout(location = 0) in vec3 a_local;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec2 a_along;
layout(location = 3) in vec3 i_origin_m;
layout(location = 4) in vec4 i_direction;  // xyz: unit direction; w: length [m]
layout(location = 5) in vec2 i_size;       // x: radius [m]; y: head length [m]
layout(location = 6) in vec4 i_color;      // rgb; a: colour-map value when u_use_colormap != 0

uniform mat4 u_view_projection;
uniform int u_use_colormap;

out vec3 v_position_m;
out vec3 v_normal;
out vec3 v_color;

void main() {
  vec3 w = normalize(i_direction.xyz);
  vec3 helper = abs(w.z) < 0.9 ? vec3(0.0, 0.0, 1.0) : vec3(1.0, 0.0, 0.0);
  vec3 u = normalize(cross(helper, w));
  vec3 v = cross(w, u);
  float radius = i_size.x;
  float along = a_along.x * i_direction.w + a_along.y * i_size.y + a_local.z * radius;
  vec3 position = i_origin_m + u * (a_local.x * radius) + v * (a_local.y * radius) + w * along;
  v_position_m = position;
  v_normal = u * a_normal.x + v * a_normal.y + w * a_normal.z;
  v_color = u_use_colormap != 0 ? autogravColormap(i_color.a) : i_color.rgb;
  gl_Position = u_view_projection * vec4(position, 1.0);
}
