// Shared lighting and fog for balls and planes. Colours arrive in sRGB; lighting is done in linear
// space and converted back, which keeps shading soft and highlights believable.

uniform vec3 u_eye;          // camera position, world space
uniform vec3 u_background;   // clear colour (sRGB); fog fades towards it
uniform float u_fog_density; // 1/m; 0 disables fog
uniform vec3 u_sun_direction; // unit vector towards the sun (the renderer's SUN_DIRECTION)

const vec3 SUN_COLOR = vec3(1.00, 0.96, 0.88);
const vec3 SKY_AMBIENT = vec3(0.34, 0.38, 0.46);
const vec3 GROUND_AMBIENT = vec3(0.16, 0.15, 0.14);

vec3 to_linear(vec3 c) { return c * c; }  // gamma 2: close to sRGB, much cheaper than pow on CPU GL
vec3 to_srgb(vec3 c) { return sqrt(max(c, vec3(0.0))); }

// x^e. Exponents 24 and 48 (the planes' and the balls' highlights; literals, so the test folds away)
// by repeated squaring: pow() is exp2(e·log2(x)), which costs a CPU rasteriser far more.
float power(float x, float e) {
    if (e == 24.0 || e == 48.0) {
        float x2 = x * x;
        float x4 = x2 * x2;
        float x8 = x4 * x4;
        float x24 = x8 * x8 * x8;
        return e == 48.0 ? x24 * x24 : x24;
    }
    return pow(x, e);
}

// Hemisphere ambient + one directional sun (Lambert) + Blinn-Phong highlight. ``sun`` is the fraction
// of the sun the point sees (1 unless shadowed), ``ambient`` the fraction of the ambient light left
// (1 unless something close hides part of the sky).
vec3 shade_lit(vec3 albedo_srgb, vec3 n, vec3 position, float shininess, float specular, float sun,
               float ambient) {
    vec3 albedo = to_linear(albedo_srgb);
    vec3 v = normalize(u_eye - position);
    float diffuse = max(dot(n, u_sun_direction), 0.0);
    vec3 sky = mix(GROUND_AMBIENT, SKY_AMBIENT, 0.5 + 0.5 * n.y) * ambient;
    vec3 h = normalize(u_sun_direction + v);
    float highlight = diffuse > 0.0 ? power(max(dot(n, h), 0.0), shininess) * specular : 0.0;
    return to_srgb(albedo * (sky + SUN_COLOR * diffuse * sun) + SUN_COLOR * highlight * sun);
}

// Exponential-squared fog towards the background with distance from the eye.
vec3 fog(vec3 color_srgb, vec3 position) {
    float d = length(position - u_eye) * u_fog_density;
    return mix(color_srgb, u_background, 1.0 - exp(-d * d));
}
