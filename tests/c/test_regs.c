/*
 * Compile-time checks of src/supi3/sdk/c/include/supi3_regs.h, built by tests/test_regmap_export_c.py with
 * gcc -std=c99 and -std=c11, -Wall -Wextra -Werror -pedantic.
 *
 * supi3_expected.h is generated at test time from the Python declaration (src/supi3/regmap): one
 * SUPI3_CHECK(macro, value); per address, reset value, field and value macro. The examples below are the
 * manual's own. Both _Static_assert and the C99 sizeof trick work at block scope, hence the checks in main().
 */
#include "supi3_regs.h"

#if defined(__STDC_VERSION__) && __STDC_VERSION__ >= 201112L
#define SUPI3_CHECK(macro, value) _Static_assert((macro) == (value), #macro " == " #value)
#else
/* C99 has no _Static_assert: a negative array size fails the build instead. */
#define SUPI3_CHECK(macro, value) (void)sizeof(char[((macro) == (value)) ? 1 : -1])
#endif

int main(void)
{
#include "supi3_expected.h"

    /* Manual examples (3.4.5, 3.4.6, Figs. 3-10 to 3-12, Table 3-8, 3.4.14). */
    SUPI3_CHECK(SUPI3_CMD_WRITE(SUPI3_SET_ADDR), 0x4Du);
    SUPI3_CHECK(SUPI3_CMD_WRITE(SUPI3_ID_ADDR), 0x4Cu);
    SUPI3_CHECK(SUPI3_CMD_READ_WRITE(SUPI3_BLOCK_TRANSFER_ADDR), SUPI3_CMD_BLOCK_TRANSFER);
    SUPI3_CHECK(SUPI3_CMD_READ(SUPI3_BLOCK_TRANSFER_ADDR), 0x8Fu);
    SUPI3_CHECK(SUPI3_SET_PCP_N_MSK | SUPI3_SET_CL_LEN_1_BYTE, 0x82u);
    SUPI3_CHECK(SUPI3_INIT_MODE_MSB_MSK | SUPI3_INIT_MODE_LSB_MSK, SUPI3_INIT_INTEL);
    SUPI3_CHECK(SUPI3_IRQ_EN_VALID_MSK, 1u << 4);
    SUPI3_CHECK(SUPI3_IRQ_EVT_IO_ACCESS_MSK, 1u << 7);
    return 0;
}
