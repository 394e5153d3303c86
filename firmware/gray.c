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
    struct gray_layout l = {bits, 0, GRAY_CODE_GRAY};
    return gray_layout_count(&l);
}

void gray_layout_for(uint32_t proj_width, uint32_t proj_height, int rows, struct gray_layout *l)
{
    l->col_bits = gray_bits_for_width(proj_width);
    l->row_bits = rows ? gray_bits_for_width(proj_height) : 0;
    l->code = GRAY_CODE_GRAY;
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

uint32_t gray_layout_count(const struct gray_layout *l)
{
    return GRAY_PATTERN_FIRST_BIT + 2u * (l->col_bits + l->row_bits);
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
    uint32_t k = (index - GRAY_PATTERN_FIRST_BIT) / 2u; /* bit, most significant first */
    int inverse = (int)((index - GRAY_PATTERN_FIRST_BIT) % 2u);
    int lit =
        k < l->col_bits
            ? (int)((gray_code_word(l->code, l->col_bits, column) >> (l->col_bits - 1u - k)) & 1u)
            : (int)((gray_code_word(l->code, l->row_bits, row) >>
                     (l->row_bits - 1u - (k - l->col_bits))) &
                    1u);
    return inverse ? !lit : lit;
}

int gray_pattern_lit(uint32_t bits, uint32_t index, uint32_t column)
{
    struct gray_layout l = {bits, 0, GRAY_CODE_GRAY};
    return gray_layout_lit(&l, index, column, 0);
}
