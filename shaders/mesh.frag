#version 330 core
// Two lights: a headlight (so nothing facing the viewer is ever black) and a key light from
// above, plus a small specular highlight to show the shape of arrows and spheres.

in vec3 v_position_m;
in vec3 v_normal;
in vec3 v_color;

uniform vec3 u_eye_m;

layout(location = 0) out vec4 o_color;

void main() {
  vec3 n = normalize(v_normal);
  vec3 to_eye = normalize(u_eye_m - v_position_m);
  if (dot(n, to_eye) < 0.0) n = -n;
  vec3 key = normalize(vec3(0.3, 0.4, 1.0));
  float head_light = max(dot(n, to_eye), 0.0);
  float key_light = max(dot(n, key), 0.0);
  float specular = pow(max(dot(reflect(-key, n), to_eye), 0.0), 24.0);
  vec3 color = v_color * (0.22 + 0.48 * head_light + 0.38 * key_light) + vec3(0.18 * specular);
  o_color = vec4(min(color, vec3(1.0)), 1.0);
}
