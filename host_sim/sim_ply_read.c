/* PLY reader for the simulated object: ASCII and binary little-endian, triangles and polygons. */
#define _POSIX_C_SOURCE 200809L
#include "sim_mesh.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum ply_type { PT_NONE, PT_I8, PT_U8, PT_I16, PT_U16, PT_I32, PT_U32, PT_F32, PT_F64 };

/* What a property is read into; x, y, z, red, green, blue and their linear floats are
 * consecutive. The scanner writes colours sRGB-encoded and linear (firmware/ply.c): the linear
 * ones are read where a file has them, as the simulator and the measurements work in linear. */
enum ply_role {
    ROLE_X,
    ROLE_Y,
    ROLE_Z,
    ROLE_FACE,
    ROLE_RED,
    ROLE_GREEN,
    ROLE_BLUE,
    ROLE_QUALITY,
    ROLE_RED_LINEAR,
    ROLE_GREEN_LINEAR,
    ROLE_BLUE_LINEAR
};

struct ply_prop {
    enum ply_type type;
    enum ply_type list_count_type; /* PT_NONE when not a list */
    int role;                      /* enum ply_role, or -1: skipped */
};

#define PLY_MAX_PROPS 32
#define PLY_MAX_ROWS (1ul << 31) /* rows of one element; more is a damaged header */
struct ply_element {
    char name[64];
    unsigned long count;
    int prop_count;
    struct ply_prop props[PLY_MAX_PROPS];
};

static enum ply_type ply_type_of(const char *s)
{
    static const struct {
        const char *name;
        enum ply_type type;
    } map[] = {{"char", PT_I8},   {"int8", PT_I8},     {"uchar", PT_U8},   {"uint8", PT_U8},
               {"short", PT_I16}, {"int16", PT_I16},   {"ushort", PT_U16}, {"uint16", PT_U16},
               {"int", PT_I32},   {"int32", PT_I32},   {"uint", PT_U32},   {"uint32", PT_U32},
               {"float", PT_F32}, {"float32", PT_F32}, {"double", PT_F64}, {"float64", PT_F64}};
    for (size_t i = 0; i < sizeof(map) / sizeof(map[0]); i++)
        if (strcmp(s, map[i].name) == 0)
            return map[i].type;
    return PT_NONE;
}

static size_t ply_type_size(enum ply_type t)
{
    static const size_t sizes[] = {0, 1, 1, 2, 2, 4, 4, 4, 8};
    return sizes[t];
}

/* Read one scalar, ASCII or binary little-endian. @retval 0 ok, -1 at end or on a bad token */
static int read_scalar(FILE *f, int binary, enum ply_type t, double *out)
{
    if (!binary)
        return fscanf(f, "%lf", out) == 1 ? 0 : -1;
    unsigned char b[8];
    size_t n = ply_type_size(t);
    if (fread(b, 1, n, f) != n)
        return -1;
    uint64_t u = 0;
    for (size_t i = 0; i < n; i++)
        u |= (uint64_t)b[i] << (8 * i);
    switch (t) {
    case PT_I8:
        *out = (int8_t)u;
        break;
    case PT_U8:
        *out = (uint8_t)u;
        break;
    case PT_I16:
        *out = (int16_t)u;
        break;
    case PT_U16:
        *out = (uint16_t)u;
        break;
    case PT_I32:
        *out = (int32_t)u;
        break;
    case PT_U32:
        *out = (uint32_t)u;
        break;
    case PT_F32: {
        uint32_t w = (uint32_t)u;
        float fl;
        memcpy(&fl, &w, 4);
        *out = fl;
        break;
    }
    case PT_F64: {
        double d;
        memcpy(&d, &u, 8);
        *out = d;
        break;
    }
    default:
        return -1;
    }
    return 0;
}

struct ply_header {
    int binary;
    int elem_count;
    struct ply_element elems[8];
};

/* The role of a vertex property (enum ply_role); -1 for one that is skipped. */
static int vertex_role(const char *name)
{
    static const char *const names[] = {[ROLE_X] = "x",
                                        [ROLE_Y] = "y",
                                        [ROLE_Z] = "z",
                                        [ROLE_FACE] = "",
                                        [ROLE_RED] = "red",
                                        [ROLE_GREEN] = "green",
                                        [ROLE_BLUE] = "blue",
                                        [ROLE_QUALITY] = "quality",
                                        [ROLE_RED_LINEAR] = "red_linear",
                                        [ROLE_GREEN_LINEAR] = "green_linear",
                                        [ROLE_BLUE_LINEAR] = "blue_linear"};
    for (int r = 0; r < (int)(sizeof(names) / sizeof(names[0])); r++)
        if (names[r][0] != '\0' && strcmp(name, names[r]) == 0)
            return r;
    return -1;
}

static int parse_header(FILE *f, struct ply_header *h, char *err, unsigned err_len,
                        const char *path)
{
    char line[256];
    memset(h, 0, sizeof(*h));
    if (fgets(line, sizeof(line), f) == NULL || strncmp(line, "ply", 3) != 0) {
        snprintf(err, err_len, "%s: not a PLY file (no 'ply' magic)", path);
        return -EINVAL;
    }
    while (fgets(line, sizeof(line), f) != NULL) {
        char a[64] = "", b[64] = "", c[64] = "", d[64] = "", e[64] = "";
        int n = sscanf(line, "%63s %63s %63s %63s %63s", a, b, c, d, e);
        if (n <= 0 || strcmp(a, "comment") == 0 || strcmp(a, "obj_info") == 0)
            continue;
        if (strcmp(a, "end_header") == 0)
            return 0;
        if (strcmp(a, "format") == 0) {
            if (strcmp(b, "ascii") == 0)
                h->binary = 0;
            else if (strcmp(b, "binary_little_endian") == 0)
                h->binary = 1;
            else {
                snprintf(err, err_len, "%s: PLY format '%s' is not supported", path, b);
                return -EINVAL;
            }
        } else if (strcmp(a, "element") == 0 && n >= 3) {
            if (h->elem_count == 8) {
                snprintf(err, err_len, "%s: more than 8 PLY elements", path);
                return -EINVAL;
            }
            struct ply_element *el = &h->elems[h->elem_count++];
            snprintf(el->name, sizeof(el->name), "%s", b);
            char *end;
            errno = 0;
            el->count = strtoul(c, &end, 10);
            /* a count that is not a number, or absurd, would loop for ever over rows of an
             * element without properties (found by make fuzz) */
            if (errno != 0 || end == c || *end != '\0' || c[0] == '-' || el->count > PLY_MAX_ROWS) {
                snprintf(err, err_len, "%s: element '%s' has a bad count '%s'", path, el->name, c);
                return -EINVAL;
            }
        } else if (strcmp(a, "property") == 0 && h->elem_count > 0) {
            struct ply_element *el = &h->elems[h->elem_count - 1];
            if (el->prop_count == PLY_MAX_PROPS) {
                snprintf(err, err_len, "%s: too many properties in '%s'", path, el->name);
                return -EINVAL;
            }
            struct ply_prop *p = &el->props[el->prop_count++];
            const char *pname = b;
            p->list_count_type = PT_NONE;
            if (strcmp(b, "list") == 0) {
                p->list_count_type = ply_type_of(c);
                p->type = ply_type_of(d);
                pname = e;
            } else {
                p->type = ply_type_of(b);
                pname = c;
            }
            if (p->type == PT_NONE || (strcmp(b, "list") == 0 && p->list_count_type == PT_NONE)) {
                snprintf(err, err_len, "%s: unknown PLY property type in '%s'", path, line);
                return -EINVAL;
            }
            p->role = -1;
            if (strcmp(el->name, "vertex") == 0 && p->list_count_type == PT_NONE)
                p->role = vertex_role(pname);
            if (strcmp(el->name, "face") == 0 && p->list_count_type != PT_NONE &&
                (strcmp(pname, "vertex_indices") == 0 || strcmp(pname, "vertex_index") == 0))
                p->role = ROLE_FACE;
        }
    }
    snprintf(err, err_len, "%s: PLY header has no end_header", path);
    return -EINVAL;
}

/* Faces are polygons: count the triangles of their fans in a first pass over the counts only
 * would need a second read, so triangles are appended to a growing array instead. */
static int push_tri(struct sim_mesh *m, uint32_t *cap, uint32_t a, uint32_t b, uint32_t c)
{
    if (m->tri_count == *cap) {
        uint32_t ncap = *cap ? *cap * 2 : 1024;
        uint32_t *t = realloc(m->tri, (size_t)ncap * 3 * sizeof(uint32_t));
        if (t == NULL)
            return -ENOMEM;
        m->tri = t;
        *cap = ncap;
    }
    m->tri[3 * m->tri_count] = a;
    m->tri[3 * m->tri_count + 1] = b;
    m->tri[3 * m->tri_count + 2] = c;
    m->tri_count++;
    return 0;
}

static int read_element(FILE *f, const struct ply_header *h, const struct ply_element *el,
                        struct sim_mesh *m, uint32_t *tri_cap)
{
    int is_vertex = strcmp(el->name, "vertex") == 0;
    if (el->prop_count == 0)
        return 0; /* rows of nothing take no bytes */
    for (unsigned long r = 0; r < el->count; r++) {
        for (int k = 0; k < el->prop_count; k++) {
            const struct ply_prop *p = &el->props[k];
            double v;
            if (p->list_count_type == PT_NONE) {
                if (read_scalar(f, h->binary, p->type, &v) != 0)
                    return -EINVAL;
                if (is_vertex && p->role >= ROLE_X && p->role <= ROLE_Z)
                    m->pos[3 * r + (unsigned long)p->role] = (float)v;
                else if (is_vertex && p->role == ROLE_QUALITY && m->quality != NULL)
                    m->quality[r] = (float)v;
                else if (is_vertex && p->role >= ROLE_RED && p->role <= ROLE_BLUE && m->rgb != NULL)
                    m->rgb[3 * r + (unsigned long)(p->role - ROLE_RED)] = (uint8_t)(v < 0     ? 0
                                                                                    : v > 255 ? 255
                                                                                              : v);
                else if (is_vertex && p->role >= ROLE_RED_LINEAR && m->rgb != NULL) {
                    double c = v < 0.0 ? 0.0 : v > 1.0 ? 1.0 : v;
                    m->rgb[3 * r + (unsigned long)(p->role - ROLE_RED_LINEAR)] =
                        (uint8_t)(c * 255.0 + 0.5);
                    if (m->lin != NULL) /* kept where red_linear is (a file of bytes and a
                                           stray float green_linear has none) */
                        m->lin[3 * r + (unsigned long)(p->role - ROLE_RED_LINEAR)] = (float)c;
                }
                continue;
            }
            double cnt;
            if (read_scalar(f, h->binary, p->list_count_type, &cnt) != 0 || cnt < 0 || cnt > 64)
                return -EINVAL;
            uint32_t idx[64];
            for (int j = 0; j < (int)cnt; j++) {
                if (read_scalar(f, h->binary, p->type, &v) != 0 || v < 0 ||
                    v >= (double)m->vert_count)
                    return -EINVAL;
                idx[j] = (uint32_t)v;
            }
            for (int j = 2; p->role == ROLE_FACE && j < (int)cnt; j++)
                if (push_tri(m, tri_cap, idx[0], idx[j - 1], idx[j]) != 0)
                    return -ENOMEM;
        }
    }
    return 0;
}

/* The fewest bytes a row of @p el can take: binary, the sum of its scalars (a list at least its
 * count); ASCII, a digit and a separator per property. */
static size_t min_row_bytes(const struct ply_header *h, const struct ply_element *el)
{
    size_t n = 0;
    for (int k = 0; k < el->prop_count; k++) {
        const struct ply_prop *p = &el->props[k];
        n += !h->binary
                 ? 2
                 : ply_type_size(p->list_count_type != PT_NONE ? p->list_count_type : p->type);
    }
    return n;
}

/* A header that claims more rows than the file holds is refused before anything is allocated
 * for them (a tiny file must not cost gigabytes: found by make fuzz). */
static int check_counts(FILE *f, const struct ply_header *h, const char *path, char *err,
                        unsigned err_len)
{
    long here = ftell(f);
    if (here < 0 || fseek(f, 0, SEEK_END) != 0)
        return 0; /* not seekable: the reads will find the end */
    long end = ftell(f);
    if (fseek(f, here, SEEK_SET) != 0)
        return -EIO;
    double left = (double)(end - here);
    for (int e = 0; e < h->elem_count; e++) {
        double need = (double)h->elems[e].count * (double)min_row_bytes(h, &h->elems[e]);
        if (need > left + 1.0) { /* + 1: ASCII without a final newline */
            snprintf(err, err_len, "%s: element '%s' claims %lu rows, more than the file holds",
                     path, h->elems[e].name, h->elems[e].count);
            return -EINVAL;
        }
        left -= need;
    }
    return 0;
}

/* Does the vertex element have a property of @p role? */
static int ply_has_role(const struct ply_header *h, enum ply_role role)
{
    for (int e = 0; e < h->elem_count; e++)
        for (int k = 0; strcmp(h->elems[e].name, "vertex") == 0 && k < h->elems[e].prop_count; k++)
            if (h->elems[e].props[k].role == (int)role)
                return 1;
    return 0;
}

/* Skip the vertex properties of roles @p first .. @p last. */
static void ply_drop_roles(struct ply_header *h, enum ply_role first, enum ply_role last)
{
    for (int e = 0; e < h->elem_count; e++)
        for (int k = 0; k < h->elems[e].prop_count; k++)
            if (h->elems[e].props[k].role >= (int)first && h->elems[e].props[k].role <= (int)last)
                h->elems[e].props[k].role = -1;
}

static int load_ply(struct sim_mesh *m, const char *path, int need_faces, char *err,
                    unsigned err_len)
{
    struct ply_header h;
    uint32_t tri_cap = 0;
    int rc;
    memset(m, 0, sizeof(*m));
    FILE *f = fopen(path, "rb");
    if (f == NULL) {
        rc = -errno;
        snprintf(err, err_len, "%s: %s", path, strerror(errno));
        return rc;
    }
    rc = parse_header(f, &h, err, err_len, path);
    if (rc == 0)
        rc = check_counts(f, &h, path, err, err_len);
    if (rc != 0)
        goto out_close;
    int vertex_elements = 0;
    for (int e = 0; e < h.elem_count; e++)
        if (strcmp(h.elems[e].name, "vertex") == 0 && vertex_elements++ == 0 &&
            h.elems[e].count < (1ul << 26))
            m->vert_count = (uint32_t)h.elems[e].count;
    rc = -EINVAL;
    if (vertex_elements > 1) { /* which would the faces index? (found by make fuzz) */
        snprintf(err, err_len, "%s: more than one vertex element", path);
        goto out_close;
    }
    if (m->vert_count == 0) {
        snprintf(err, err_len, "%s: no vertices (or more than 2^26)", path);
        goto out_close;
    }
    m->pos = calloc((size_t)m->vert_count * 3, sizeof(float));
    m->normal = calloc((size_t)m->vert_count * 3, sizeof(float));
    int has_rgb = ply_has_role(&h, ROLE_RED) || ply_has_role(&h, ROLE_RED_LINEAR);
    int has_quality = ply_has_role(&h, ROLE_QUALITY);
    int has_lin = ply_has_role(&h, ROLE_RED_LINEAR);
    if (has_lin)
        ply_drop_roles(&h, ROLE_RED, ROLE_BLUE); /* the sRGB bytes only repeat them */
    if (has_rgb)
        m->rgb = calloc((size_t)m->vert_count * 3, 1);
    if (has_lin)
        m->lin = calloc((size_t)m->vert_count * 3, sizeof(float));
    if (has_quality)
        m->quality = calloc(m->vert_count, sizeof(float));
    if (m->pos == NULL || m->normal == NULL || (has_rgb && m->rgb == NULL) ||
        (has_lin && m->lin == NULL) || (has_quality && m->quality == NULL)) {
        rc = -ENOMEM;
        snprintf(err, err_len, "%s: out of memory", path);
        goto out_free;
    }
    for (int e = 0; e < h.elem_count; e++) {
        rc = read_element(f, &h, &h.elems[e], m, &tri_cap);
        if (rc != 0) {
            snprintf(err, err_len, "%s: element '%s' is truncated or has a bad value", path,
                     h.elems[e].name);
            goto out_free;
        }
    }
    if (m->tri_count == 0 && need_faces) {
        rc = -EINVAL;
        snprintf(err, err_len, "%s: no faces", path);
        goto out_free;
    }
    fclose(f);
    sim_mesh_compute_normals(m);
    return 0;
out_free:
    sim_mesh_free(m);
out_close:
    fclose(f);
    return rc;
}

int sim_mesh_load_ply(struct sim_mesh *m, const char *path, char *err, unsigned err_len)
{
    return load_ply(m, path, 1, err, err_len);
}

int sim_mesh_load_ply_points(struct sim_mesh *m, const char *path, char *err, unsigned err_len)
{
    return load_ply(m, path, 0, err, err_len);
}
