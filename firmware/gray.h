/* Gray-code pattern set for projector columns: order of the stored sequence and bit coding. */
#ifndef GRAY_H
#define GRAY_H

#include <stdint.h>

/* Stored sequence: 0 = full white, 1 = full black, then for each bit (most significant first)
 * the bit's stripes, followed by their inverse for the finest inverse_bits bits (all of them by
 * default: 2 + 2k = bit k's stripes, 3 + 2k = their inverse); gray_layout_bit says where. */
#define GRAY_PATTERN_WHITE 0u
#define GRAY_PATTERN_BLACK 1u
#define GRAY_PATTERN_FIRST_BIT 2u

/** How the bits of a coordinate are projected. */
enum gray_code {
    GRAY_CODE_GRAY = 0, /**< reflected binary Gray code, each bit its own stripes */
    /** XOR-04 (Gupta et al. 2012): every bit coarser than bit 1 (stripes 4 wide) projected XOR
     *  bit 1, so every pattern has fine stripes: light bounced between surfaces is about the same
     *  under a pattern and its inverse and cannot flip a bit. One code set, no voting. */
    GRAY_CODE_XOR04 = 1,
};

/** The stored sequence: white, black, each column bit (most significant first) with its inverse
 *  after it where it has one, then, when row_bits > 0, each row bit likewise. */
struct gray_layout {
    uint32_t col_bits, row_bits;
    uint32_t code; /**< enum gray_code */
    /** Of each coordinate, the finest bits projected with their inverse (0: every bit); a
     *  coarser bit is read against the mean of white and black (decode.c). */
    uint32_t inverse_bits;
};

/** Layout for a projector; @p rows = 0 codes columns only. */
void gray_layout_for(uint32_t proj_width, uint32_t proj_height, int rows, struct gray_layout *l);
/** Patterns in the stored sequence. */
uint32_t gray_layout_count(const struct gray_layout *l);
/** Where bit @p k (most significant first) of the columns (@p is_row 0) or the rows is stored.
 *  @param pattern  out: its stripes' index @param inverse  out: their inverse's, or -1: none */
void gray_layout_bit(const struct gray_layout *l, int is_row, uint32_t k, uint32_t *pattern,
                     int32_t *inverse);
/** What pattern @p index shows. @param is_row, k  out: its coordinate and bit (most significant
 *  first) @param inverse  out: 1 the bit's inverse @retval 0 a bit's pattern @retval -1 white,
 *  black or beyond the sequence */
int gray_layout_pattern(const struct gray_layout *l, uint32_t index, int *is_row, uint32_t *k,
                        int *inverse);
/** Whether projector pixel (column, row) is lit in pattern @p index. @retval 1 lit, 0 dark */
int gray_layout_lit(const struct gray_layout *l, uint32_t index, uint32_t column, uint32_t row);

/** The word of pattern bits (bit b: the pattern of Gray bit b, 0 the finest) that @p code
 *  projects for @p value, of @p bits bits: the Gray code, or its XOR-04 form. */
uint32_t gray_code_word(uint32_t code, uint32_t bits, uint32_t value);
/** The value whose word is @p word (the inverse of gray_code_word). */
uint32_t gray_code_value(uint32_t code, uint32_t bits, uint32_t word);
/** The pattern bits of @p code (of @p bits) that XOR-04 projects XOR its base bit: 0 for Gray. */
uint32_t gray_code_xor_mask(uint32_t code, uint32_t bits);

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
