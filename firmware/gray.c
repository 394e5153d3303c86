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
    struct gray_layout l = {bits, 0};
    return gray_layout_count(&l);
}

void gray_layout_for(uint32_t proj_width, uint32_t proj_height, int rows, struct gray_layout *l)
{
    l->col_bits = gray_bits_for_width(proj_width);
    l->row_bits = rows ? gray_bits_for_width(proj_height) : 0;
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
    int lit = k < l->col_bits
                  ? (int)((gray_encode(column) >> (l->col_bits - 1u - k)) & 1u)
                  : (int)((gray_encode(row) >> (l->row_bits - 1u - (k - l->col_bits))) & 1u);
    return inverse ? !lit : lit;
}

int gray_pattern_lit(uint32_t bits, uint32_t index, uint32_t column)
{
    struct gray_layout l = {bits, 0};
    return gray_layout_lit(&l, index, column, 0);
}
