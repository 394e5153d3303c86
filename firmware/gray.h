/* Gray-code pattern set for projector columns: order of the stored sequence and bit coding. */
#ifndef GRAY_H
#define GRAY_H

#include <stdint.h>

/* Stored sequence: 0 = full white, 1 = full black, then for each bit k (most significant first)
 * 2 + 2k = the bit's stripes, 3 + 2k = their inverse. */
#define GRAY_PATTERN_WHITE 0u
#define GRAY_PATTERN_BLACK 1u
#define GRAY_PATTERN_FIRST_BIT 2u

/** The stored sequence: white, black, each column bit and its inverse (most significant first),
 *  then, when row_bits > 0, each row bit and its inverse. */
struct gray_layout {
    uint32_t col_bits, row_bits;
};

/** Layout for a projector; @p rows = 0 codes columns only. */
void gray_layout_for(uint32_t proj_width, uint32_t proj_height, int rows, struct gray_layout *l);
/** Patterns in the stored sequence. */
uint32_t gray_layout_count(const struct gray_layout *l);
/** Whether projector pixel (column, row) is lit in pattern @p index. @retval 1 lit, 0 dark */
int gray_layout_lit(const struct gray_layout *l, uint32_t index, uint32_t column, uint32_t row);

/** Bits needed to code @p proj_width columns. @retval bit count (1..16) */
uint32_t gray_bits_for_width(uint32_t proj_width);
/** Number of patterns of a columns-only sequence of @p bits bits. */
uint32_t gray_pattern_count(uint32_t bits);
/** Gray code of a binary number. */
uint32_t gray_encode(uint32_t binary);
/** Binary number of a Gray code. */
uint32_t gray_decode(uint32_t gray);
/** Columns-only: whether column @p column is lit in pattern @p index. @retval 1 lit, 0 dark */
int gray_pattern_lit(uint32_t bits, uint32_t index, uint32_t column);

#endif
