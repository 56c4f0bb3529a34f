/* The sprite program: one vertex shader that places a quad as its material
 * faces (camera, velocity, axis, world plane) with the minimum footprint,
 * and one fragment shader that draws a built-in sprite or a texture cell,
 * optionally lit. Every formula here is in the man page. */
#include "render/render_internal.h"

#include <math.h>
#include <stdio.h>

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
    "#version 330 core\n"
    "layout(location = 0) in vec2 corner;\n"
    "layout(location = 1) in vec4 centre_size;\n"
    "layout(location = 2) in vec4 colour;\n"
    "layout(location = 3) in vec4 turn;\n"   /* angle, material, frame, variant */
    "layout(location = 4) in vec4 motion;\n" /* velocity, length */
    "uniform mat4 view;\n"
    "uniform mat4 proj;\n"
    "uniform float px_per_unit;\n"
    "uniform float min_px;\n"
    "uniform int align;\n"
    "uniform vec3 axis;\n"
    "uniform vec3 plane_x;\n"
    "uniform vec3 plane_y;\n"
    "out vec2 v_corner;\n"
    "out vec4 v_colour;\n"
    "flat out vec2 v_frame;\n"
    "flat out vec3 v_ax;\n"
    "flat out vec3 v_ay;\n"
    "void main() {\n"
    "    vec4 c = view * vec4(centre_size.xyz, 1.0);\n"
    "    float hx = 0.5 * centre_size.w, hy = hx;\n"
    "    float s = sin(turn.x), k = cos(turn.x);\n"
    "    vec3 ax = vec3(k, s, 0.0), ay = vec3(-s, k, 0.0);\n"
    "    if (align == 1) {\n"
    "        vec2 d = (mat3(view) * motion.xyz).xy;\n"
    "        float L = length(d);\n"
    "        if (L > 1e-20) {\n"
    "            ay = vec3(d / L, 0.0);\n"
    "            ax = vec3(ay.y, -ay.x, 0.0);\n"
    "        }\n"
    "        hy = 0.5 * motion.w;\n"
    "    } else if (align == 2) {\n"
    "        vec3 sight = proj[3][3] > 0.5 ? vec3(0.0, 0.0, 1.0) : normalize(-c.xyz);\n"
    "        vec3 side = cross(axis, sight);\n"
    "        float L = length(side);\n"
    "        ay = axis;\n"
    "        ax = L > 1e-12 ? side / L : vec3(k, s, 0.0);\n"
    "    } else if (align == 3) {\n"
    "        ax = k * plane_x + s * plane_y;\n"
    "        ay = -s * plane_x + k * plane_y;\n"
    "    }\n"
    "    float w = proj[2][3] * c.z + proj[3][3];\n"
    "    float gx = max(1.0, min_px * w / (2.0 * hx * px_per_unit));\n"
    "    float gy = max(1.0, min_px * w / (2.0 * hy * px_per_unit));\n"
    "    if (!(hx > 0.0) || !(hy > 0.0)) gx = gy = 1.0;\n"
    "    vec3 p = c.xyz + ax * (corner.x * hx * gx) + ay * (corner.y * hy * gy);\n"
    "    gl_Position = proj * vec4(p, 1.0);\n"
    "    v_corner = corner;\n"
    "    v_colour = colour / (gx * gy);\n"
    "    v_frame = turn.zw;\n"
    "    v_ax = ax;\n"
    "    v_ay = ay;\n"
    "}\n";

/* The built-in sprites as functions of the corner coordinate q (f = 0 is
 * discarded), a texture cell (with the flipbook's cross-fade), and the
 * light: ambient + colour max(0, n . l) with n the sprite's spherical
 * normal (x, y, sqrt(1 - d^2)) in its own axes, or the normal map's. */
static const char *fragment_src =
    "#version 330 core\n"
    "in vec2 v_corner;\n"
    "in vec4 v_colour;\n"
    "flat in vec2 v_frame;\n"
    "flat in vec3 v_ax;\n"
    "flat in vec3 v_ay;\n"
    "uniform int kind;\n"
    "uniform bool textured;\n"
    "uniform sampler2D tex;\n"
    "uniform vec2 grid;\n"
    "uniform float frames;\n"
    "uniform bool frame_loop;\n"
    "uniform bool frame_blend;\n"
    "uniform bool lit;\n"
    "uniform bool normal_mapped;\n"
    "uniform sampler2D normal_tex;\n"
    "uniform vec3 light_dir;\n" /* towards the light, view space */
    "uniform vec3 light_color;\n"
    "uniform vec3 ambient;\n"
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
    "    if (kind == 1) { vec2 s = 1.0 - q * q; return s.x * s.x * s.y * s.y; }\n"
    "    if (kind == 2) {\n"
    "        float e = q.x * q.x * 9.0 + q.y * q.y;\n"
    "        if (e >= 1.0) return 0.0;\n"
    "        float core = max(0.0, 1.0 - e * 6.0);\n"
    "        return (1.0 - e) * (1.0 - e) + 2.0 * core * core * core;\n"
    "    }\n"
    "    if (kind == 3) {\n"
    "        if (d2 >= 1.0) return 0.0;\n"
    "        vec2 p = q * 1.7 + vec2(37.0, 17.0) * v_frame.y;\n"
    "        float n = 0.65 * noise(p) + 0.35 * noise(p * 2.3 + 5.0);\n"
    "        float k = 1.0 - d2;\n"
    "        return k * sqrt(k) * clamp(1.6 * n - 0.15, 0.0, 1.0);\n"
    "    }\n"
    "    if (kind == 4) {\n"
    "        if (d2 >= 1.0) return 0.0;\n"
    "        float k = 1.0 - d2, a = abs(q.x), b = abs(q.y);\n"
    "        float rays = max(0.0, 1.0 - a * 14.0) * (1.0 - b) * (1.0 - b)\n"
    "                   + max(0.0, 1.0 - b * 14.0) * (1.0 - a) * (1.0 - a);\n"
    "        float core = max(0.0, 1.0 - d2 * 16.0);\n"
    "        return 0.35 * k * k * k + 0.8 * rays + 2.0 * core * core;\n"
    "    }\n"
    "    if (kind == 5) {\n"
    "        float t = (sqrt(d2) - 0.72) / 0.22;\n"
    "        return t * t < 1.0 ? (1.0 - t * t) * (1.0 - t * t) : 0.0;\n"
    "    }\n"
    "    if (d2 >= 1.0) return 0.0;\n"
    "    return (1.0 - d2) * (1.0 - d2);\n"
    "}\n"
    "vec2 cell_uv(float cell, vec2 uv) {\n"
    "    float col = mod(cell, grid.x), row = floor(cell / grid.x);\n"
    "    return (vec2(col, row) + uv) / grid;\n"
    "}\n"
    "vec4 texel(vec2 uv) {\n" /* uv: (0, 0) the top left of the cell */
    "    float a = floor(v_frame.x), t = v_frame.x - a;\n"
    "    vec4 x = texture(tex, cell_uv(a, uv));\n"
    "    if (!frame_blend || t <= 0.0) return x;\n"
    "    float b = a + 1.0;\n"
    "    b = frame_loop ? mod(b, frames) : min(b, frames - 1.0);\n"
    "    return mix(x, texture(tex, cell_uv(b, uv)), t);\n"
    "}\n"
    "void main() {\n"
    "    vec2 q = v_corner, uv = vec2(0.5 + 0.5 * q.x, 0.5 - 0.5 * q.y);\n"
    "    vec4 base;\n"
    "    if (textured) {\n"
    "        base = texel(uv);\n"
    "    } else {\n"
    "        float f = shape(q);\n"
    "        if (f <= 0.0) discard;\n"
    "        base = vec4(f);\n"
    "    }\n"
    "    frag = v_colour * base;\n"
    "    if (lit) {\n"
    "        vec3 az = cross(v_ax, v_ay);\n"
    "        vec3 n;\n"
    "        if (normal_mapped) {\n"
    "            vec3 m = texture(normal_tex, cell_uv(floor(v_frame.x), uv)).xyz * 2.0 - 1.0;\n"
    "            n = normalize(v_ax * m.x + v_ay * m.y + az * m.z);\n"
    "        } else {\n"
    "            float d2 = min(dot(q, q), 1.0);\n"
    "            n = v_ax * q.x + v_ay * q.y + az * sqrt(1.0 - d2);\n"
    "        }\n"
    "        frag.rgb *= ambient + light_color * max(0.0, dot(n, light_dir));\n"
    "    }\n"
    "}\n";

/* Ribbons: world-space triangles (render/ribbons_from_sim.c has already
 * turned them to the camera), premultiplied colour interpolated between
 * the strip's points, times the cross-section over `across`. */
static const char *ribbon_vertex_src =
    "#version 330 core\n"
    "layout(location = 0) in vec4 pos_across;\n"
    "layout(location = 1) in vec4 colour;\n"
    "layout(location = 2) in float profile;\n"
    "uniform mat4 view;\n"
    "uniform mat4 proj;\n"
    "out float v_across;\n"
    "out vec4 v_colour;\n"
    "flat out float v_profile;\n"
    "void main() {\n"
    "    gl_Position = proj * (view * vec4(pos_across.xyz, 1.0));\n"
    "    v_across = pos_across.w;\n"
    "    v_colour = colour;\n"
    "    v_profile = profile;\n"
    "}\n";

static const char *ribbon_fragment_src = "#version 330 core\n"
                                         "in float v_across;\n"
                                         "in vec4 v_colour;\n"
                                         "flat in float v_profile;\n"
                                         "layout(location = 0) out vec4 frag;\n"
                                         "void main() {\n"
                                         "    float k = max(0.0, 1.0 - v_across * v_across);\n"
                                         "    frag = v_colour * mix(k * k, 1.0, v_profile);\n"
                                         "}\n";

static GLuint compile_shader(pfx_renderer *r, GLenum type, const char *src, pfx_diags *d) {
    GLuint s = r->gl.CreateShader(type);
    r->gl.ShaderSource(s, 1, &src, NULL);
    r->gl.CompileShader(s);
    GLint ok = GL_FALSE;
    r->gl.GetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[512] = "";
        r->gl.GetShaderInfoLog(s, sizeof log, NULL, log);
        pfx_diag_error(d, "cannot compile %s shader: %s",
                       type == GL_VERTEX_SHADER ? "vertex" : "fragment", log);
        r->gl.DeleteShader(s);
        return 0;
    }
    return s;
}

static void find_uniforms(pfx_renderer *r) {
    pfx_sprite_uniforms *u = &r->u;
    GLuint p = r->program;
#define PFX_UNIFORM(name) u->name = r->gl.GetUniformLocation(p, #name);
    PFX_UNIFORM(view) PFX_UNIFORM(proj) PFX_UNIFORM(px_per_unit) PFX_UNIFORM(min_px);
    PFX_UNIFORM(align) PFX_UNIFORM(axis) PFX_UNIFORM(plane_x) PFX_UNIFORM(plane_y);
    PFX_UNIFORM(kind) PFX_UNIFORM(textured) PFX_UNIFORM(tex) PFX_UNIFORM(grid);
    PFX_UNIFORM(frames) PFX_UNIFORM(frame_loop) PFX_UNIFORM(frame_blend);
    PFX_UNIFORM(lit) PFX_UNIFORM(normal_mapped) PFX_UNIFORM(normal_tex);
    PFX_UNIFORM(light_dir) PFX_UNIFORM(light_color) PFX_UNIFORM(ambient);
#undef PFX_UNIFORM
}

/* Compiles and links one program; 0 (with an error naming `what`) on
 * failure. */
static GLuint build_program(pfx_renderer *r, const char *vsrc, const char *fsrc, const char *what,
                            pfx_diags *d) {
    GLuint vs = compile_shader(r, GL_VERTEX_SHADER, vsrc, d);
    if (!vs)
        return 0;
    GLuint fs = compile_shader(r, GL_FRAGMENT_SHADER, fsrc, d);
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
        pfx_diag_error(d, "cannot link %s shader: %s", what, log);
        r->gl.DeleteProgram(p);
        return 0;
    }
    return p;
}

bool pfx_shader_build(pfx_renderer *r, pfx_diags *d) {
    r->program = build_program(r, vertex_src, fragment_src, "sprite", d);
    r->ribbon_program = build_program(r, ribbon_vertex_src, ribbon_fragment_src, "ribbon", d);
    if (!r->program || !r->ribbon_program)
        return false;
    r->ribbon_view = r->gl.GetUniformLocation(r->ribbon_program, "view");
    r->ribbon_proj = r->gl.GetUniformLocation(r->ribbon_program, "proj");
    find_uniforms(r);
    r->gl.UseProgram(r->program);
    r->gl.Uniform1i(r->u.tex, 0);
    r->gl.Uniform1i(r->u.normal_tex, 1);
    return true;
}

/* A world direction in view space (the view matrix's rotation). */
static void to_view(const pfx_view *v, const double w[3], float out[3]) {
    const double *m = v->m;
    for (int row = 0; row < 3; row++)
        out[row] = (float)(m[row] * w[0] + m[4 + row] * w[1] + m[8 + row] * w[2]);
}

void pfx_shader_frame(pfx_renderer *r, const pfx_view *v, const pfx_render_settings *s) {
    float view[16], proj[16], l[3];
    for (int i = 0; i < 16; i++) {
        view[i] = (float)v->m[i];
        proj[i] = (float)v->proj[i];
    }
    const pfx_sprite_uniforms *u = &r->u;
    r->gl.UniformMatrix4fv(u->view, 1, GL_FALSE, view);
    r->gl.UniformMatrix4fv(u->proj, 1, GL_FALSE, proj);
    r->gl.Uniform1f(u->px_per_unit, (float)(v->proj[5] * 0.5 * r->height));
    r->gl.Uniform1f(u->min_px, (float)PFX_MIN_FOOTPRINT_PX);
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

void pfx_shader_material(pfx_renderer *r, const pfx_view *v, const pfx_gpu_material *g) {
    const pfx_material *m = &g->m;
    const pfx_sprite_uniforms *u = &r->u;
    float a[3], px[3], py[3];
    double bx[3], by[3];
    to_view(v, m->axis, a);
    plane_basis(m->axis, bx, by);
    to_view(v, bx, px);
    to_view(v, by, py);
    r->gl.Uniform1i(u->align, (GLint)m->align);
    r->gl.Uniform3f(u->axis, a[0], a[1], a[2]);
    r->gl.Uniform3f(u->plane_x, px[0], px[1], px[2]);
    r->gl.Uniform3f(u->plane_y, py[0], py[1], py[2]);
    r->gl.Uniform1i(u->kind, (GLint)m->sprite);
    r->gl.Uniform1i(u->textured, g->texture != 0);
    r->gl.Uniform2f(u->grid, (float)m->cols, (float)m->rows);
    r->gl.Uniform1f(u->frames, (float)m->frames);
    r->gl.Uniform1i(u->frame_loop, m->frame_loop);
    r->gl.Uniform1i(u->frame_blend, m->frame_blend);
    r->gl.Uniform1i(u->lit, m->lit);
    r->gl.Uniform1i(u->normal_mapped, g->normal_map != 0);
    r->gl.ActiveTexture(GL_TEXTURE0);
    r->gl.BindTexture(GL_TEXTURE_2D, g->texture);
    r->gl.ActiveTexture(GL_TEXTURE1);
    r->gl.BindTexture(GL_TEXTURE_2D, g->normal_map);
    r->gl.ActiveTexture(GL_TEXTURE0);
}
