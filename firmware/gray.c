/* Gray-code pattern set: which projector columns each stored pattern lights. */
#include "gray.h"

uint32_t gray_bits_for_width(uint32_t proj_width)
{
    uint32_t bits = 1;
    while ((1u << bits) < proj_width && bits < 16)
        bits++;
    return bits;
}

uint32_t gray_pattern_count(uint32_t bits)
{
    struct gray_layout l = {bits, 0, GRAY_CODE_GRAY, 0};
    return gray_layout_count(&l);
}

void gray_layout_for(uint32_t proj_width, uint32_t proj_height, int rows, struct gray_layout *l)
{
    l->col_bits = gray_bits_for_width(proj_width);
    l->row_bits = rows ? gray_bits_for_width(proj_height) : 0;
    l->code = GRAY_CODE_GRAY;
    l->inverse_bits = 0;
}

/* XOR-04's base is Gray bit 1 (stripes 4 projector pixels wide); the bits above it ride on it. */
#define XOR04_BASE 1u

uint32_t gray_code_xor_mask(uint32_t code, uint32_t bits)
{
    if (code != GRAY_CODE_XOR04 || bits <= XOR04_BASE + 1u)
        return 0;
    return ((1u << bits) - 1u) & ~((2u << XOR04_BASE) - 1u);
}

uint32_t gray_code_word(uint32_t code, uint32_t bits, uint32_t value)
{
    uint32_t g = gray_encode(value);
    return (g >> XOR04_BASE) & 1u ? g ^ gray_code_xor_mask(code, bits) : g;
}

uint32_t gray_code_value(uint32_t code, uint32_t bits, uint32_t word)
{
    /* XOR with the base again gives the Gray code back: the base bit itself is not changed. */
    uint32_t g = (word >> XOR04_BASE) & 1u ? word ^ gray_code_xor_mask(code, bits) : word;
    return gray_decode(g);
}

/* Bits of a coordinate of @p bits that have an inverse pattern: the finest. */
static uint32_t inverses(const struct gray_layout *l, uint32_t bits)
{
    return l->inverse_bits == 0 || l->inverse_bits > bits ? bits : l->inverse_bits;
}

/* Patterns of a coordinate of @p bits. */
static uint32_t axis_patterns(const struct gray_layout *l, uint32_t bits)
{
    return bits + inverses(l, bits);
}

uint32_t gray_layout_count(const struct gray_layout *l)
{
    return GRAY_PATTERN_FIRST_BIT + axis_patterns(l, l->col_bits) + axis_patterns(l, l->row_bits);
}

void gray_layout_bit(const struct gray_layout *l, int is_row, uint32_t k, uint32_t *pattern,
                     int32_t *inverse)
{
    uint32_t bits = is_row ? l->row_bits : l->col_bits;
    uint32_t base = GRAY_PATTERN_FIRST_BIT + (is_row ? axis_patterns(l, l->col_bits) : 0u);
    uint32_t plain = bits - inverses(l, bits); /* the coarsest, alone */
    if (k < plain) {
        *pattern = base + k;
        *inverse = -1;
    } else {
        *pattern = base + plain + 2u * (k - plain);
        *inverse = (int32_t)*pattern + 1;
    }
}

int gray_layout_pattern(const struct gray_layout *l, uint32_t index, int *is_row, uint32_t *k,
                        int *inverse)
{
    if (index < GRAY_PATTERN_FIRST_BIT || index >= gray_layout_count(l))
        return -1;
    uint32_t i = index - GRAY_PATTERN_FIRST_BIT, cols = axis_patterns(l, l->col_bits);
    *is_row = i >= cols;
    i -= *is_row ? cols : 0u;
    uint32_t bits = *is_row ? l->row_bits : l->col_bits;
    uint32_t plain = bits - inverses(l, bits);
    *k = i < plain ? i : plain + (i - plain) / 2u;
    *inverse = i >= plain && (i - plain) % 2u == 1u;
    return 0;
}

uint32_t gray_encode(uint32_t binary)
{
    return binary ^ (binary >> 1);
}

uint32_t gray_decode(uint32_t gray)
{
    /* Prefix XOR from the top bit down. */
    for (uint32_t shift = 1; shift < 32; shift <<= 1)
        gray ^= gray >> shift;
    return gray;
}

int gray_layout_lit(const struct gray_layout *l, uint32_t index, uint32_t column, uint32_t row)
{
    if (index == GRAY_PATTERN_WHITE)
        return 1;
    if (index == GRAY_PATTERN_BLACK)
        return 0;
    int is_row, inverse;
    uint32_t k; /* bit, most significant first */
    if (gray_layout_pattern(l, index, &is_row, &k, &inverse) != 0)
        return 0;
    uint32_t bits = is_row ? l->row_bits : l->col_bits;
    int lit = (int)((gray_code_word(l->code, bits, is_row ? row : column) >> (bits - 1u - k)) & 1u);
    return inverse ? !lit : lit;
}

int gray_pattern_lit(uint32_t bits, uint32_t index, uint32_t column)
{
    struct gray_layout l = {bits, 0, GRAY_CODE_GRAY, 0};
    return gray_layout_lit(&l, index, column, 0);
}
