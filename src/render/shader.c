/* The sprite program: one vertex shader that places a quad as its material
 * faces (camera, velocity, axis, world plane) with the minimum footprint,
 * and one fragment shader that draws a built-in sprite or a texture cell,
 * optionally lit. Every formula here is in the man page. */
#include "render/render_internal.h"

#include <math.h>
#include <stdio.h>

/* The level of detail a textured sprite samples is explicit, one per
 * sprite, so that every GL implementation reads the same mip levels: left
 * implicit, each approximates its own from differences between
 * neighbouring pixels (an H100 and llvmpipe were 26/255 apart on flipbook
 * sprites a few pixels wide). It is the GL specification's lambda =
 * log2(rho) at the sprite's centre: with J the 2x2 Jacobian from the
 * cell's texels (u, v) to pixels (x, y), rho = max(|(du/dx, dv/dx)|,
 * |(du/dy, dv/dy)|), the lengths of the columns of J^-1, which for J's
 * columns a = dpixel/du and b = dpixel/dv are |(a.y, b.y)| / |det J| and
 * |(a.x, b.x)| / |det J|. A column is the projection's derivative along a
 * quad axis at the centre, d(ndc) = (dclip.xy - ndc dclip.w) / clip.w,
 * times half the viewport, over the cell's texels on that axis. A quad
 * facing the camera (camera, velocity alignment) lies at one depth, so
 * this is exactly the lambda of each of its pixels; a quad tilted in depth
 * (axis, world) reads its centre's level all over. The colour texture and
 * the normal map have one each (their sizes may differ).
 *
 * The level read is GL's nearest one (level k for lambda in [k - 0.5,
 * k + 0.5)), except within 1 / (2 PFX_LOD_BLEND) of a half-way point,
 * where the two levels are blended linearly across the band: the colour is
 * then continuous in lambda, so two implementations whose float maths
 * differ in the last bits of lambda cannot land a whole level apart, and a
 * sprite that grows or shrinks does not pop from level to level. Outside
 * the band one level is read, as before, and llvmpipe fetches only it. */
#define PFX_LOD_BLEND "4.0"

/* The level textureLod reads for lambda (the rule above), in front of
 * every program's sources. */
static const char *mip_src =
    "float mip_level(float lambda) {\n"
    "    float k = floor(lambda);\n"
    "    return k + clamp(" PFX_LOD_BLEND " * (lambda - k - 0.5) + 0.5, 0.0, 1.0);\n"
    "}\n";

/* Each instance is a unit quad with corners (+-1, +-1). Its two axes ax, ay
 * (view space) and half-extents hx, hy come from the material's alignment:
 *   camera:   the view plane, turned by angle;
 *   velocity: ay along the velocity projected on the view plane, hy half
 *             the sprite's length, hx half its size (no velocity: camera);
 *   axis:     ay the world axis, ax perpendicular to it and to the line of
 *             sight (the axial billboard);
 *   world:    the plane of the material's normal, turned by angle.
 * A side that would be narrower than min_px pixels is widened to min_px and
 * the colour divided by the widening, so the sprite's summed brightness
 * (its falloff integrates to width x height) is the same at any size. The
 * corner coordinate goes to the fragment shader unchanged. */
static const char *vertex_src =
    "layout(location = 0) in vec2 corner;\n"
    "layout(location = 1) in vec4 centre_size;\n"
    "layout(location = 2) in vec4 colour;\n"
    "layout(location = 3) in vec4 turn;\n"   /* angle, material, frame, variant */
    "layout(location = 4) in vec4 motion;\n" /* velocity, length */
    "uniform mat4 view;\n"
    "uniform mat4 proj;\n"
    "uniform float px_per_unit;\n"
    "uniform float min_px;\n"
    "uniform vec3 axis;\n"
    "uniform vec3 plane_x;\n"
    "uniform vec3 plane_y;\n"
    "uniform vec2 viewport;\n"
    "uniform vec2 cell_texels;\n"
    "uniform vec2 normal_texels;\n"
    "out vec2 v_corner;\n"
    "out vec4 v_colour;\n"
    "flat out vec2 v_frame;\n"
    "flat out vec3 v_ax;\n"
    "flat out vec3 v_ay;\n"
    "#if TEXTURED || NORMAL_MAPPED\n"
    "flat out vec2 v_lod;\n"
    "#endif\n"
    "#if SHADOWED\n"
    "uniform mat4 shadow_from_view;\n"
    "out vec3 v_shadow;\n"
    "#endif\n"
    "#if MOTION\n"
    "layout(location = 5) in vec4 mv_end;\n" /* centre at the next frame, weight */
    "uniform vec2 mv_size;\n"
    "flat out vec3 v_mv;\n"
    "#endif\n"
    "float lod(vec2 a, vec2 b, vec2 texels) {\n"
    "    a /= texels.x;\n"
    "    b /= texels.y;\n"
    "    float det = abs(a.x * b.y - a.y * b.x);\n"
    "    float m = max(length(vec2(a.x, b.x)), length(vec2(a.y, b.y)));\n"
    "    return mip_level(det > 0.0 ? log2(m) - log2(det) : 1e3);\n"
    "}\n"
    "void main() {\n"
    "    vec4 c = view * vec4(centre_size.xyz, 1.0);\n"
    "    float hx = 0.5 * centre_size.w, hy = hx;\n"
    "    float s = sin(turn.x), k = cos(turn.x);\n"
    "    vec3 ax = vec3(k, s, 0.0), ay = vec3(-s, k, 0.0);\n"
    "#if ALIGN == 1\n"
    "    vec2 d = (mat3(view) * motion.xyz).xy;\n"
    "    float L = length(d);\n"
    "    if (L > 1e-20) {\n"
    "        ay = vec3(d / L, 0.0);\n"
    "        ax = vec3(ay.y, -ay.x, 0.0);\n"
    "    }\n"
    "    hy = 0.5 * motion.w;\n"
    "#elif ALIGN == 2\n"
    "    vec3 sight = proj[3][3] > 0.5 ? vec3(0.0, 0.0, 1.0) : normalize(-c.xyz);\n"
    "    vec3 side = cross(axis, sight);\n"
    "    float L = length(side);\n"
    "    ay = axis;\n"
    "    ax = L > 1e-12 ? side / L : vec3(k, s, 0.0);\n"
    "#elif ALIGN == 3\n"
    "    ax = k * plane_x + s * plane_y;\n"
    "    ay = -s * plane_x + k * plane_y;\n"
    "#endif\n"
    "    float w = proj[2][3] * c.z + proj[3][3];\n"
    "    float gx = max(1.0, min_px * w / (2.0 * hx * px_per_unit));\n"
    "    float gy = max(1.0, min_px * w / (2.0 * hy * px_per_unit));\n"
    "    if (!(hx > 0.0) || !(hy > 0.0)) gx = gy = 1.0;\n"
    "    vec3 p = c.xyz + ax * (corner.x * hx * gx) + ay * (corner.y * hy * gy);\n"
    "    gl_Position = proj * vec4(p, 1.0);\n"
    "#if TEXTURED || NORMAL_MAPPED\n"
    "    vec4 e = proj * c;\n"
    "    vec2 ndc = e.xy / e.w;\n"
    "    vec4 du = proj * vec4(ax * (2.0 * hx * gx), 0.0);\n"
    "    vec4 dv = proj * vec4(ay * (2.0 * hy * gy), 0.0);\n"
    "    vec2 ju = (du.xy - ndc * du.w) / e.w * 0.5 * viewport;\n"
    "    vec2 jv = (dv.xy - ndc * dv.w) / e.w * 0.5 * viewport;\n"
    "    v_lod = vec2(lod(ju, jv, cell_texels), lod(ju, jv, normal_texels));\n"
    "#endif\n"
    "    v_corner = corner;\n"
    "    v_colour = colour / (gx * gy);\n"
    "    v_frame = turn.zw;\n"
    "    v_ax = ax;\n"
    "    v_ay = ay;\n"
    "#if SHADOWED\n"
    "    v_shadow = (shadow_from_view * vec4(p, 1.0)).xyz;\n"
    "#endif\n"
    "#if MOTION\n"
    "    vec4 a = proj * c;\n"
    "    vec4 b = proj * (view * vec4(mv_end.xyz, 1.0));\n"
    "    float opacity = mv_end.w * (colour.a > 0.0 ? colour.a : 1.0) / (gx * gy);\n"
    "    v_mv = a.w > 1e-6 && b.w > 1e-6\n"
    "               ? vec3((b.xy / b.w - a.xy / a.w) * 0.5 * mv_size, opacity) : vec3(0.0);\n"
    "#endif\n"
    "}\n";

/* The built-in sprites as functions of the corner coordinate q (f = 0 is
 * discarded), a texture cell (with the flipbook's cross-fade), and the
 * light: ambient + colour max(0, n . l) with n the sprite's spherical
 * normal (x, y, sqrt(1 - d^2)) in its own axes, or the normal map's; the
 * direct term times exp(-optical depth) from the shadow volume where the
 * material is shadowed (render/shadow.h). */
static const char *fragment_src =
    "in vec2 v_corner;\n"
    "in vec4 v_colour;\n"
    "flat in vec2 v_frame;\n"
    "flat in vec3 v_ax;\n"
    "flat in vec3 v_ay;\n"
    "#if TEXTURED || NORMAL_MAPPED\n"
    "flat in vec2 v_lod;\n"
    "#endif\n"
    "#if MOTION\n"
    "flat in vec3 v_mv;\n"
    "#endif\n"
    "uniform sampler2D tex;\n"
    "uniform vec2 grid;\n"
    "uniform float frames;\n"
    "uniform bool frame_loop;\n"
    "uniform sampler2D normal_tex;\n"
    "uniform vec3 light_dir;\n" /* towards the light, view space */
    "uniform vec3 light_color;\n"
    "uniform vec3 ambient;\n"
    "#if SHADOWED\n"
    "in vec3 v_shadow;\n"
    "uniform sampler3D shadow_tex;\n"
    "#endif\n"
    "layout(location = 0) out vec4 frag;\n"
    "float hash(vec2 p) {\n"
    "    uvec2 u = uvec2(ivec2(floor(p)) + 32768);\n"
    "    uint h = u.x * 0x8da6b343u ^ u.y * 0xd8163841u;\n"
    "    h ^= h >> 15; h *= 0x2c1b3c6du; h ^= h >> 12;\n"
    "    return float(h & 0xffffu) / 65535.0;\n"
    "}\n"
    "float noise(vec2 p) {\n" /* value noise, smooth between lattice points */
    "    vec2 i = floor(p), f = fract(p), u = f * f * (3.0 - 2.0 * f);\n"
    "    return mix(mix(hash(i), hash(i + vec2(1, 0)), u.x),\n"
    "               mix(hash(i + vec2(0, 1)), hash(i + vec2(1, 1)), u.x), u.y);\n"
    "}\n"
    "float shape(vec2 q) {\n"
    "    float d2 = dot(q, q);\n"
    "#if KIND == 1\n"
    "    vec2 s = 1.0 - q * q; return s.x * s.x * s.y * s.y;\n"
    "#elif KIND == 2\n"
    "    float e = q.x * q.x * 9.0 + q.y * q.y;\n"
    "    if (e >= 1.0) return 0.0;\n"
    "    float core = max(0.0, 1.0 - e * 6.0);\n"
    "    return (1.0 - e) * (1.0 - e) + 2.0 * core * core * core;\n"
    "#elif KIND == 3\n"
    "    if (d2 >= 1.0) return 0.0;\n"
    "    vec2 p = q * 1.7 + vec2(37.0, 17.0) * v_frame.y;\n"
    "    float n = 0.65 * noise(p) + 0.35 * noise(p * 2.3 + 5.0);\n"
    "    float k = 1.0 - d2;\n"
    "    return k * sqrt(k) * clamp(1.6 * n - 0.15, 0.0, 1.0);\n"
    "#elif KIND == 4\n"
    "    if (d2 >= 1.0) return 0.0;\n"
    "    float k = 1.0 - d2, a = abs(q.x), b = abs(q.y);\n"
    "    float rays = max(0.0, 1.0 - a * 14.0) * (1.0 - b) * (1.0 - b)\n"
    "               + max(0.0, 1.0 - b * 14.0) * (1.0 - a) * (1.0 - a);\n"
    "    float core = max(0.0, 1.0 - d2 * 16.0);\n"
    "    return 0.35 * k * k * k + 0.8 * rays + 2.0 * core * core;\n"
    "#elif KIND == 5\n"
    "    float t = (sqrt(d2) - 0.72) / 0.22;\n"
    "    return t * t < 1.0 ? (1.0 - t * t) * (1.0 - t * t) : 0.0;\n"
    "#else\n"
    "    if (d2 >= 1.0) return 0.0;\n"
    "    return (1.0 - d2) * (1.0 - d2);\n"
    "#endif\n"
    "}\n"
    "vec2 cell_uv(float cell, vec2 uv) {\n" /* the row from a quotient half a cell off an
                                                 integer: an approximate division (a GPU's)
                                                 cannot land a row off, as floor(cell / cols)
                                                 can */
    "    float row = floor((cell + 0.5) / grid.x), col = cell - row * grid.x;\n"
    "    return (vec2(col, row) + uv) / grid;\n"
    "}\n"
    "#if TEXTURED\n"
    "vec4 texel(vec2 uv) {\n" /* uv: (0, 0) the top left of the cell */
    "    float a = floor(v_frame.x), t = v_frame.x - a;\n"
    "    vec4 x = textureLod(tex, cell_uv(a, uv), v_lod.x);\n"
    "#if FRAME_BLEND\n"
    "    if (t <= 0.0) return x;\n"
    "    float b = a + 1.0;\n"
    "    b = b < frames ? b : frame_loop ? 0.0 : frames - 1.0;\n"
    "    return mix(x, textureLod(tex, cell_uv(b, uv), v_lod.x), t);\n"
    "#else\n"
    "    return x;\n"
    "#endif\n"
    "}\n"
    "#endif\n"
    "void main() {\n"
    "    vec2 q = v_corner, uv = vec2(0.5 + 0.5 * q.x, 0.5 - 0.5 * q.y);\n"
    "#if TEXTURED\n"
    "    vec4 base = texel(uv);\n"
    "#else\n"
    "    float f = shape(q);\n"
    "    if (f <= 0.0) discard;\n"
    "    vec4 base = vec4(f);\n"
    "#endif\n"
    "#if MOTION\n"
    "    float w = clamp(base.a * v_mv.z, 0.0, 1.0);\n"
    "    frag = vec4(v_mv.xy * w, w, w);\n"
    "#else\n"
    "    frag = v_colour * base;\n"
    "#endif\n"
    "#if LIT\n"
    "    vec3 az = cross(v_ax, v_ay);\n"
    "#if NORMAL_MAPPED\n"
    "    vec3 m = textureLod(normal_tex, cell_uv(floor(v_frame.x), uv), v_lod.y).xyz * 2.0 - 1.0;\n"
    "    vec3 n = normalize(v_ax * m.x + v_ay * m.y + az * m.z);\n"
    "#else\n"
    "    float d2 = min(dot(q, q), 1.0);\n"
    "    vec3 n = v_ax * q.x + v_ay * q.y + az * sqrt(1.0 - d2);\n"
    "#endif\n"
    "    float direct = max(0.0, dot(n, light_dir));\n"
    "#if SHADOWED\n"
    "    direct *= exp(-texture(shadow_tex, v_shadow).r);\n"
    "#endif\n"
    "    frag.rgb *= ambient + light_color * direct;\n"
    "#endif\n"
    "}\n";

/* Ribbons: world-space triangles (render/ribbons_from_sim.c has already
 * turned them to the camera), premultiplied colour interpolated between
 * the strip's points, times the cross-section over `across`, times the
 * texture (when the run's material has one) at u = along, v = (1 -
 * across) / 2: the image's left edge at the head, its top on the +1 edge.
 * A strip's texels per pixel change along it, so its lambda is the
 * specification's formula at each pixel, rho the longer of the texel
 * steps d(u, v)/dx and d(u, v)/dy: pfx's own, from the interpolated
 * coordinates' differences, which are exact where the strip is flat on
 * screen, rather than each implementation's approximation of it. */
static const char *ribbon_vertex_src =
    "layout(location = 0) in vec4 pos_across;\n"
    "layout(location = 1) in vec4 colour;\n"
    "layout(location = 2) in vec2 profile_along;\n"
    "uniform mat4 view;\n"
    "uniform mat4 proj;\n"
    "out float v_across;\n"
    "out float v_along;\n"
    "out vec4 v_colour;\n"
    "flat out float v_profile;\n"
    "void main() {\n"
    "    gl_Position = proj * (view * vec4(pos_across.xyz, 1.0));\n"
    "    v_across = pos_across.w;\n"
    "    v_along = profile_along.y;\n"
    "    v_colour = colour;\n"
    "    v_profile = profile_along.x;\n"
    "}\n";

static const char *ribbon_fragment_src =
    "in float v_across;\n"
    "in float v_along;\n"
    "in vec4 v_colour;\n"
    "flat in float v_profile;\n"
    "uniform sampler2D tex;\n"
    "uniform bool textured;\n"
    "layout(location = 0) out vec4 frag;\n"
    "void main() {\n"
    "    float k = max(0.0, 1.0 - v_across * v_across);\n"
    "    frag = v_colour * mix(k * k, 1.0, v_profile);\n"
    "    if (textured) {\n"
    "        vec2 st = vec2(v_along, 0.5 - 0.5 * v_across), size = vec2(textureSize(tex, 0));\n"
    "        float rho = max(length(dFdx(st) * size), length(dFdy(st) * size));\n"
    "        frag *= textureLod(tex, st, mip_level(log2(max(rho, 1e-20))));\n"
    "    }\n"
    "}\n";

/* One program per combination of what the material switches (sprite
 * kind, texture, cross-fade, light, normal map, alignment), chosen by
 * #defines in front of the sources rather than by uniforms: llvmpipe runs
 * both sides of a branch under a mask, so one program with every path in
 * it cost every path on every fragment (a plain round sprite paid for the
 * smoke noise, the texture fetches and the light). */
static GLuint compile_shader(pfx_renderer *r, GLenum type, const char *defines, const char *src,
                             pfx_diags *d) {
    GLuint s = r->gl.CreateShader(type);
    const char *parts[4] = {"#version 330 core\n", defines, mip_src, src};
    r->gl.ShaderSource(s, 4, parts, NULL);
    r->gl.CompileShader(s);
    GLint ok = GL_FALSE;
    r->gl.GetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[512] = "";
        r->gl.GetShaderInfoLog(s, sizeof log, NULL, log);
        pfx_diag_error(d, PFX_RULE_RENDERER_FAILED, "cannot compile %s shader: %s",
                       type == GL_VERTEX_SHADER ? "vertex" : "fragment", log);
        r->gl.DeleteShader(s);
        return 0;
    }
    return s;
}

static void find_uniforms(pfx_renderer *r, pfx_program *prog) {
    pfx_sprite_uniforms *u = &prog->u;
    GLuint p = prog->id;
#define PFX_UNIFORM(name) u->name = r->gl.GetUniformLocation(p, #name);
    PFX_UNIFORM(view) PFX_UNIFORM(proj) PFX_UNIFORM(px_per_unit) PFX_UNIFORM(min_px);
    PFX_UNIFORM(axis) PFX_UNIFORM(plane_x) PFX_UNIFORM(plane_y);
    PFX_UNIFORM(tex) PFX_UNIFORM(grid) PFX_UNIFORM(frames) PFX_UNIFORM(frame_loop);
    PFX_UNIFORM(normal_tex) PFX_UNIFORM(light_dir) PFX_UNIFORM(light_color);
    PFX_UNIFORM(ambient) PFX_UNIFORM(mv_size) PFX_UNIFORM(shadow_tex);
    PFX_UNIFORM(shadow_from_view) PFX_UNIFORM(viewport) PFX_UNIFORM(cell_texels);
    PFX_UNIFORM(normal_texels);
#undef PFX_UNIFORM
}

/* The switches of a material as one number. */
static unsigned program_key(const pfx_gpu_material *g) {
    const pfx_material *m = &g->m;
    bool textured = g->texture != 0, lit = m->lit;
    return (unsigned)m->sprite | (unsigned)m->align << 4 | (unsigned)textured << 8 |
           (unsigned)(textured && m->frame_blend) << 9 | (unsigned)lit << 10 |
           (unsigned)(lit && g->normal_map != 0) << 11 | (unsigned)(lit && m->shadowed) << 13;
}

/* Compiles both stages with `defines` in front and links them; 0 (with an
 * error naming `what`) on failure. */
static GLuint build_program(pfx_renderer *r, const char *defines, const char *vsrc,
                            const char *fsrc, const char *what, pfx_diags *d) {
    GLuint vs = compile_shader(r, GL_VERTEX_SHADER, defines, vsrc, d);
    if (!vs)
        return 0;
    GLuint fs = compile_shader(r, GL_FRAGMENT_SHADER, defines, fsrc, d);
    if (!fs) {
        r->gl.DeleteShader(vs);
        return 0;
    }
    GLuint p = r->gl.CreateProgram();
    r->gl.AttachShader(p, vs);
    r->gl.AttachShader(p, fs);
    r->gl.LinkProgram(p);
    r->gl.DeleteShader(vs); /* flagged; freed with the program */
    r->gl.DeleteShader(fs);
    GLint ok = GL_FALSE;
    r->gl.GetProgramiv(p, GL_LINK_STATUS, &ok);
    if (!ok) {
        char log[512] = "";
        r->gl.GetProgramInfoLog(p, sizeof log, NULL, log);
        pfx_diag_error(d, PFX_RULE_RENDERER_FAILED, "cannot link %s shader: %s", what, log);
        r->gl.DeleteProgram(p);
        return 0;
    }
    return p;
}

/* The motion-vector variant of a program (render/motion_vectors.c): the
 * same quad and falloff, writing motion instead of colour; light does not
 * move anything, so it is switched off there. */
#define PFX_PROGRAM_MOTION (1u << 12)

static bool link_program(pfx_renderer *r, pfx_program *prog, pfx_diags *d) {
    char defines[240];
    unsigned k = prog->key;
    snprintf(defines, sizeof defines,
             "#define KIND %u\n#define ALIGN %u\n#define TEXTURED %u\n#define FRAME_BLEND %u\n"
             "#define LIT %u\n#define NORMAL_MAPPED %u\n#define MOTION %u\n#define SHADOWED %u\n",
             k & 15u, (k >> 4) & 15u, (k >> 8) & 1u, (k >> 9) & 1u, (k >> 10) & 1u, (k >> 11) & 1u,
             (k >> 12) & 1u, (k >> 13) & 1u);
    prog->id = build_program(r, defines, vertex_src, fragment_src, "sprite", d);
    if (!prog->id)
        return false;
    find_uniforms(r, prog);
    r->gl.UseProgram(prog->id);
    r->gl.Uniform1i(prog->u.tex, 0);
    r->gl.Uniform1i(prog->u.normal_tex, 1);
    r->gl.Uniform1i(prog->u.shadow_tex, 2);
    return true;
}

bool pfx_shader_build_ribbon(pfx_renderer *r, pfx_diags *d) {
    r->ribbon_program = build_program(r, "", ribbon_vertex_src, ribbon_fragment_src, "ribbon", d);
    if (!r->ribbon_program)
        return false;
    r->ribbon_view = r->gl.GetUniformLocation(r->ribbon_program, "view");
    r->ribbon_proj = r->gl.GetUniformLocation(r->ribbon_program, "proj");
    r->ribbon_textured = r->gl.GetUniformLocation(r->ribbon_program, "textured");
    r->gl.UseProgram(r->ribbon_program);
    r->gl.Uniform1i(r->gl.GetUniformLocation(r->ribbon_program, "tex"), 0);
    return true;
}

/* The index of the program for `key`, linked the first time it is asked
 * for; false (with an error) when it cannot be. */
static bool find_program(pfx_renderer *r, unsigned key, size_t *index, pfx_diags *d) {
    for (size_t i = 0; i < r->program_count; i++)
        if (r->programs[i].key == key) {
            *index = i;
            return true;
        }
    if (r->program_count == PFX_MAX_PROGRAMS) {
        pfx_diag_error(d, PFX_RULE_TOO_MANY, "more than %d different sprite programs",
                       PFX_MAX_PROGRAMS);
        return false;
    }
    pfx_program *prog = &r->programs[r->program_count];
    prog->key = key;
    if (!link_program(r, prog, d))
        return false;
    *index = r->program_count++;
    return true;
}

bool pfx_shader_bind(pfx_renderer *r, pfx_gpu_material *g, pfx_diags *d) {
    return find_program(r, program_key(g), &g->program, d);
}

/* A world direction in view space (the view matrix's rotation). */
static void to_view(const pfx_view *v, const double w[3], float out[3]) {
    const double *m = v->m;
    for (int row = 0; row < 3; row++)
        out[row] = (float)(m[row] * w[0] + m[4 + row] * w[1] + m[8 + row] * w[2]);
}

/* The camera and the light, for the program about to draw. */
static void set_frame(pfx_renderer *r, const pfx_sprite_uniforms *u, const pfx_view *v,
                      const pfx_render_settings *s) {
    float view[16], proj[16], l[3];
    for (int i = 0; i < 16; i++) {
        view[i] = (float)v->m[i];
        proj[i] = (float)v->proj[i];
    }
    r->gl.UniformMatrix4fv(u->view, 1, GL_FALSE, view);
    r->gl.UniformMatrix4fv(u->proj, 1, GL_FALSE, proj);
    r->gl.Uniform1f(u->px_per_unit, (float)(v->proj[5] * 0.5 * r->height));
    r->gl.Uniform1f(u->min_px, (float)PFX_MIN_FOOTPRINT_PX);
    r->gl.Uniform2f(u->viewport, (float)r->width, (float)r->height);
    const double towards[3] = {-s->light_dir[0], -s->light_dir[1], -s->light_dir[2]};
    to_view(v, towards, l);
    r->gl.Uniform3f(u->light_dir, l[0], l[1], l[2]);
    r->gl.Uniform3f(u->light_color, s->light_color[0], s->light_color[1], s->light_color[2]);
    r->gl.Uniform3f(u->ambient, s->ambient[0], s->ambient[1], s->ambient[2]);
}

/* Two unit vectors spanning the plane of unit normal n (world). */
static void plane_basis(const double n[3], double x[3], double y[3]) {
    const double *h = fabs(n[1]) < 0.9 ? (const double[3]){0, 1, 0} : (const double[3]){1, 0, 0};
    x[0] = h[1] * n[2] - h[2] * n[1];
    x[1] = h[2] * n[0] - h[0] * n[2];
    x[2] = h[0] * n[1] - h[1] * n[0];
    double len = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
    for (int i = 0; i < 3; i++)
        x[i] /= len;
    y[0] = n[1] * x[2] - n[2] * x[1];
    y[1] = n[2] * x[0] - n[0] * x[2];
    y[2] = n[0] * x[1] - n[1] * x[0];
}

/* The shadow volume's coordinates of a view-space point: its map from
 * world points times the inverse of the (rigid) view matrix, whose
 * rotation is R (columns 0..2 of m) and translation t: world = R^T (p - t).
 * Without a volume the depth reads 0 everywhere: unshadowed. */
static void set_shadow(pfx_renderer *r, const pfx_sprite_uniforms *u, const pfx_view *v) {
    const double *m = v->m, *s = r->shadow_from_world;
    double inv[16] = {0};
    for (int row = 0; row < 3; row++)
        for (int col = 0; col < 3; col++)
            inv[col * 4 + row] = m[row * 4 + col];
    for (int row = 0; row < 3; row++)
        inv[12 + row] = -(inv[row] * m[12] + inv[4 + row] * m[13] + inv[8 + row] * m[14]);
    inv[15] = 1;
    float f[16];
    for (int col = 0; col < 4; col++)
        for (int row = 0; row < 4; row++) {
            double x = 0;
            for (int k = 0; k < 4; k++)
                x += s[k * 4 + row] * inv[col * 4 + k];
            f[col * 4 + row] = (float)x;
        }
    if (!r->shadow_on) /* far outside the volume's texture: depth 0 at its clamped edge */
        for (int i = 0; i < 16; i++)
            f[i] = i == 12 || i == 13 || i == 14 ? -1.0f : i == 15 ? 1.0f : 0.0f;
    r->gl.UniformMatrix4fv(u->shadow_from_view, 1, GL_FALSE, f);
    r->gl.ActiveTexture(GL_TEXTURE2);
    r->gl.BindTexture(GL_TEXTURE_3D, r->shadow_tex);
    r->gl.ActiveTexture(GL_TEXTURE0);
}

/* The texels of one flipbook cell of img (1 x 1 without an image), for
 * the level of detail. */
static void set_texels(pfx_renderer *r, GLint at, const pfx_material *m, const pfx_image *img) {
    if (img)
        r->gl.Uniform2f(at, (float)img->width / (float)m->cols,
                        (float)img->height / (float)m->rows);
    else
        r->gl.Uniform2f(at, 1.0f, 1.0f);
}

/* Makes `prog` current with g's uniforms. */
static void use_program(pfx_renderer *r, const pfx_view *v, const pfx_render_settings *s,
                        const pfx_gpu_material *g, const pfx_program *prog) {
    const pfx_material *m = &g->m;
    const pfx_sprite_uniforms *u = &prog->u;
    r->gl.UseProgram(prog->id);
    set_frame(r, u, v, s);
    float a[3], px[3], py[3];
    double bx[3], by[3];
    to_view(v, m->axis, a);
    plane_basis(m->axis, bx, by);
    to_view(v, bx, px);
    to_view(v, by, py);
    r->gl.Uniform3f(u->axis, a[0], a[1], a[2]);
    r->gl.Uniform3f(u->plane_x, px[0], px[1], px[2]);
    r->gl.Uniform3f(u->plane_y, py[0], py[1], py[2]);
    r->gl.Uniform2f(u->grid, (float)m->cols, (float)m->rows);
    set_texels(r, u->cell_texels, m, m->texture);
    set_texels(r, u->normal_texels, m, m->normal_map);
    r->gl.Uniform1f(u->frames, (float)m->frames);
    r->gl.Uniform1i(u->frame_loop, m->frame_loop);
    r->gl.ActiveTexture(GL_TEXTURE0);
    r->gl.BindTexture(GL_TEXTURE_2D, g->texture);
    r->gl.ActiveTexture(GL_TEXTURE1);
    r->gl.BindTexture(GL_TEXTURE_2D, g->normal_map);
    r->gl.ActiveTexture(GL_TEXTURE0);
    if (u->shadow_from_view >= 0)
        set_shadow(r, u, v);
}

void pfx_shader_material(pfx_renderer *r, const pfx_view *v, const pfx_render_settings *s,
                         const pfx_gpu_material *g) {
    use_program(r, v, s, g, &r->programs[g->program]);
}

bool pfx_shader_motion(pfx_renderer *r, const pfx_view *v, const pfx_render_settings *s,
                       const pfx_gpu_material *g, pfx_diags *d) {
    const unsigned lit = 1u << 10 | 1u << 11 | 1u << 13;
    size_t i;
    if (!find_program(r, (program_key(g) & ~lit) | PFX_PROGRAM_MOTION, &i, d))
        return false;
    const pfx_program *prog = &r->programs[i];
    use_program(r, v, s, g, prog);
    r->gl.Uniform2f(prog->u.mv_size, (float)r->width, (float)r->height);
    return true;
}
