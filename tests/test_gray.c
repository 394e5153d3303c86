/* Gray-code pattern set: coding properties the decoder relies on. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "gray.h"

static void test_bits_for_width(void **state)
{
    (void)state;
    assert_int_equal(gray_bits_for_width(1024), 10);
    assert_int_equal(gray_bits_for_width(1025), 11);
    assert_int_equal(gray_bits_for_width(1920), 11);
    assert_int_equal(gray_bits_for_width(2), 1);
    assert_int_equal(gray_pattern_count(10), 22);
}

static void test_roundtrip_and_single_bit_steps(void **state)
{
    (void)state;
    for (uint32_t c = 0; c < 4096; c++) {
        assert_int_equal(gray_decode(gray_encode(c)), c);
        if (c > 0) {
            uint32_t diff = gray_encode(c) ^ gray_encode(c - 1);
            assert_true(diff != 0 && (diff & (diff - 1)) == 0); /* exactly one bit */
        }
    }
}

/* Reading every pattern pair of a column as the decoder does gives the column back. */
static void test_patterns_code_every_column(void **state)
{
    (void)state;
    const uint32_t width = 1024, bits = gray_bits_for_width(width);
    for (uint32_t c = 0; c < width; c++) {
        assert_int_equal(gray_pattern_lit(bits, GRAY_PATTERN_WHITE, c), 1);
        assert_int_equal(gray_pattern_lit(bits, GRAY_PATTERN_BLACK, c), 0);
        uint32_t code = 0;
        for (uint32_t k = 0; k < bits; k++) {
            int pos = gray_pattern_lit(bits, GRAY_PATTERN_FIRST_BIT + 2 * k, c);
            int neg = gray_pattern_lit(bits, GRAY_PATTERN_FIRST_BIT + 2 * k + 1, c);
            assert_int_equal(pos, !neg);
            code = (code << 1) | (uint32_t)pos;
        }
        assert_int_equal(gray_decode(code), c);
    }
}

/* XOR-04: every column's patterns read back to the column; no pattern has stripes wider than 4
 * projector pixels but the base's own (the point: bounced light evens out under each); and
 * across a base stripe edge only the base and the bits riding on it change. */
static void test_xor04_codes_every_column_in_fine_stripes(void **state)
{
    (void)state;
    const uint32_t width = 1024, bits = gray_bits_for_width(width);
    struct gray_layout l = {bits, 0, GRAY_CODE_XOR04, 0};
    uint32_t longest_run[16] = {0}, run[16] = {0};
    int last[16];
    for (uint32_t c = 0; c < width; c++) {
        uint32_t word = 0;
        for (uint32_t k = 0; k < bits; k++) {
            int pos = gray_layout_lit(&l, GRAY_PATTERN_FIRST_BIT + 2 * k, c, 0);
            assert_int_equal(pos, !gray_layout_lit(&l, GRAY_PATTERN_FIRST_BIT + 2 * k + 1, c, 0));
            word = (word << 1) | (uint32_t)pos;
            run[k] = c > 0 && pos == last[k] ? run[k] + 1 : 1;
            longest_run[k] = run[k] > longest_run[k] ? run[k] : longest_run[k];
            last[k] = pos;
        }
        assert_int_equal(word, gray_code_word(GRAY_CODE_XOR04, bits, c));
        assert_int_equal(gray_code_value(GRAY_CODE_XOR04, bits, word), c);
        assert_int_equal(gray_code_value(GRAY_CODE_GRAY, bits, gray_encode(c)), c);
    }
    for (uint32_t k = 0; k + 1 < bits; k++) /* every pattern but the finest: stripes of 4 */
        assert_true(longest_run[k] <= 4);
    assert_int_equal(gray_code_xor_mask(GRAY_CODE_XOR04, bits), 0x3FCu);
    assert_int_equal(gray_code_xor_mask(GRAY_CODE_GRAY, bits), 0);
}

/* Inverses for the finest 3 bits only: each coordinate's coarse bits alone, then the fine ones
 * each with its inverse, columns then rows; gray_layout_bit and gray_layout_pattern name the
 * same patterns, every index is one of them, and every column and row still reads back. */
static void test_fewer_inverses_sequence(void **state)
{
    (void)state;
    struct gray_layout l = {10, 8, GRAY_CODE_GRAY, 3};
    assert_int_equal(gray_layout_count(&l), 2 + (10 + 3) + (8 + 3));
    uint32_t p;
    int32_t inv;
    gray_layout_bit(&l, 0, 0, &p, &inv);
    assert_true(p == 2 && inv == -1); /* the coarsest column bit first, alone */
    gray_layout_bit(&l, 0, 7, &p, &inv);
    assert_true(p == 9 && inv == 10); /* the first of the finest three, with its inverse */
    gray_layout_bit(&l, 0, 9, &p, &inv);
    assert_true(p == 13 && inv == 14);
    gray_layout_bit(&l, 1, 0, &p, &inv);
    assert_true(p == 15 && inv == -1); /* the rows after every column pattern */
    unsigned seen[64] = {0};
    for (int is_row = 0; is_row < 2; is_row++) {
        for (uint32_t k = 0; k < (is_row ? 8u : 10u); k++) {
            gray_layout_bit(&l, is_row, k, &p, &inv);
            int r, i;
            uint32_t kk;
            assert_int_equal(gray_layout_pattern(&l, p, &r, &kk, &i), 0);
            assert_true(r == is_row && kk == k && i == 0);
            seen[p]++;
            if (inv >= 0) {
                assert_int_equal(gray_layout_pattern(&l, (uint32_t)inv, &r, &kk, &i), 0);
                assert_true(r == is_row && kk == k && i == 1);
                seen[inv]++;
            }
        }
    }
    for (uint32_t i = 2; i < gray_layout_count(&l); i++)
        assert_int_equal(seen[i], 1);
    int r, i;
    uint32_t kk;
    assert_int_equal(gray_layout_pattern(&l, gray_layout_count(&l), &r, &kk, &i), -1);
    assert_int_equal(gray_layout_pattern(&l, GRAY_PATTERN_BLACK, &r, &kk, &i), -1);
    for (uint32_t c = 0; c < 1024; c += 7) { /* the stripes read back to the column */
        uint32_t word = 0;
        for (uint32_t k = 0; k < 10; k++) {
            gray_layout_bit(&l, 0, k, &p, &inv);
            int lit = gray_layout_lit(&l, p, c, 5);
            if (inv >= 0)
                assert_int_equal(gray_layout_lit(&l, (uint32_t)inv, c, 5), !lit);
            word = (word << 1) | (uint32_t)lit;
        }
        assert_int_equal(gray_code_value(GRAY_CODE_GRAY, 10, word), c);
    }
    l.inverse_bits = 16; /* more than a coordinate has: every bit */
    assert_int_equal(gray_layout_count(&l), 2 + 2 * (10 + 8));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bits_for_width),
        cmocka_unit_test(test_roundtrip_and_single_bit_steps),
        cmocka_unit_test(test_patterns_code_every_column),
        cmocka_unit_test(test_xor04_codes_every_column_in_fine_stripes),
        cmocka_unit_test(test_fewer_inverses_sequence),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
