/**
 * IBS SUPI 3 OPC serial uP interface: register addresses, field masks and interface bytes.
 * Generated from src/supi3/regmap (python -m supi3.regmap --write-checked-in). Do not edit.
 * Source: IBS SUPI 3 OPC UM E, revision 05, 04/2009, 3.4.3 to 3.4.14.
 * Layout decisions for the manual's missing figures: docs/assumptions/regmap.md (RM-n; UP-n are in
 * docs/assumptions/upif.md). A macro that rests on one ends in a comment naming it (assumption RM-n):
 *   RM-1: command byte RD = bit 7, WR = bit 6, A3..0 = bits 3..0
 *   RM-2: the command byte with A = 15 itself starts the block transfer
 *   RM-3: init byte mode bit reflected into bits 7 and 0
 *   RM-4: SET /PCP = bit 7, ExtReg = bit 6, ID12..8 = bits 4..0, CL = bits 2..0
 *   RM-5: reads 8/9 LENGTH = bits 5..0, MEDIUM = bit 6, ENABLE = bit 7
 *   RM-6: read 10 LEVEL = bits 3..0, ENABLE = bit 7; read 11 OUT_LEVEL = bits 3..0, BRANCH_LEVEL = bits 7..4
 *   RM-7: interrupt bits D6..D0 = PCMD, INVALID, VALID, ID, RESET, PCP RX, PCP TX
 *   RM-8: I/O access bit D7 is live and not cleared by reading
 *   UP-21: sub-byte data lengths use the low bits of byte 0
 *
 * _ADDR is the address A3..0 for the command byte; where Table 3-10 names a different write and read
 * register at one address, each has its own _ADDR. _POS is a field's lowest bit, _MSK its mask in
 * position; field value macros are in position too. Accesses: r read, w write, rc read-clear.
 *
 * Addr  Write                                Read
 *    0  IN0: INTERBUS IN byte 0 (w)          OUT0: INTERBUS OUT byte 0 (r)
 *    1  IN1: INTERBUS IN byte 1 (w)          OUT1: INTERBUS OUT byte 1 (r)
 *    2  IN2: INTERBUS IN byte 2 (w)          OUT2: INTERBUS OUT byte 2 (r)
 *    3  IN3: INTERBUS IN byte 3 (w)          OUT3: INTERBUS OUT byte 3 (r)
 *    4  Reserved (reserved-ignored)          Reserved (reserved-ignored)
 *    5  Reserved (reserved-ignored)          Reserved (reserved-ignored)
 *    6  - (no-effect)                        Reserved (reserved-zero)
 *    7  ALARM: Processor alarm register (w)  PCMD: Processor command register (r)
 *    8  - (no-effect)                        LENGTH_OUT: Length of the outgoing interface (r)
 *    9  - (no-effect)                        LENGTH_BRANCH: Length of the bus branch (r)
 *   10  - (no-effect)                        POWER_IN: Power level of the incoming interface, enable (r)
 *   11  - (no-effect)                        POWER_OUT_BRANCH: Power level of the branch and the outgoing interface (r)
 *   12  ID: ID code (w)                      ID: ID code (r)
 *   13  SET: SET register (w)                SET: SET register (r)
 *   14  IRQ_EN: Interrupt enable (w)         IRQ_EVT: Interrupt event (rc)
 *   15  Block transfer (block-transfer)      Block transfer (block-transfer)
 */
#ifndef SUPI3_REGS_H
#define SUPI3_REGS_H

#define SUPI3_ADDR_COUNT                          16u
#define SUPI3_BLOCK_TRANSFER_ADDR                 0x0Fu

/* CMD: Command byte (3.4.4, 3.4.6, Fig. 3-8, Figs. 3-10 to 3-12). Not addressable. */
#define   SUPI3_CMD_RD_POS                        7u    /* assumption RM-1 */
#define   SUPI3_CMD_RD_MSK                        0x80u /* assumption RM-1 */
#define   SUPI3_CMD_WR_POS                        6u    /* assumption RM-1 */
#define   SUPI3_CMD_WR_MSK                        0x40u /* assumption RM-1 */
#define   SUPI3_CMD_A_POS                         0u    /* assumption RM-1 */
#define   SUPI3_CMD_A_MSK                         0x0Fu /* assumption RM-1 */
#define SUPI3_CMD_BLOCK_TRANSFER                  0xCFu /* assumptions RM-1, RM-2 */

/* INIT: Initialization byte (3.4.3, Table 3-8). Not addressable. */
#define   SUPI3_INIT_MODE_MSB_POS                 7u    /* assumption RM-3 */
#define   SUPI3_INIT_MODE_MSB_MSK                 0x80u /* assumption RM-3 */
#define   SUPI3_INIT_MODE_LSB_POS                 0u    /* assumption RM-3 */
#define   SUPI3_INIT_MODE_LSB_MSK                 0x01u /* assumption RM-3 */
#define SUPI3_INIT_MOTOROLA                       0x00u /* assumption RM-3 */
#define SUPI3_INIT_INTEL                          0x81u /* assumption RM-3 */

/* Command byte for a read, a write, or (Motorola only) a simultaneous read and write of address addr. */
#define SUPI3_CMD_A(addr)                         (((addr) << SUPI3_CMD_A_POS) & SUPI3_CMD_A_MSK) /* assumption RM-1 */
#define SUPI3_CMD_READ(addr)                      (SUPI3_CMD_RD_MSK | SUPI3_CMD_A(addr)) /* assumption RM-1 */
#define SUPI3_CMD_WRITE(addr)                     (SUPI3_CMD_WR_MSK | SUPI3_CMD_A(addr)) /* assumption RM-1 */
#define SUPI3_CMD_READ_WRITE(addr)                (SUPI3_CMD_RD_MSK | SUPI3_CMD_WR_MSK | SUPI3_CMD_A(addr)) /* assumption RM-1 */

/* IN0: INTERBUS IN byte 0. Address 0, write (w).
 * Ref: 3.4.8. Cleared by: power-up, interbus reset. */
#define SUPI3_IN0_ADDR                            0x00u
#define SUPI3_IN0_RESET                           0x00u
#define   SUPI3_IN0_DATA_POS                      0u    /* assumption UP-21 */
#define   SUPI3_IN0_DATA_MSK                      0xFFu /* assumption UP-21 */

/* OUT0: INTERBUS OUT byte 0. Address 0, read (r).
 * Ref: 3.4.8. Cleared by: power-up, interbus reset. */
#define SUPI3_OUT0_ADDR                           0x00u
#define SUPI3_OUT0_RESET                          0x00u
#define   SUPI3_OUT0_DATA_POS                     0u    /* assumption UP-21 */
#define   SUPI3_OUT0_DATA_MSK                     0xFFu /* assumption UP-21 */

/* IN1: INTERBUS IN byte 1. Address 1, write (w).
 * Ref: 3.4.8. Cleared by: power-up, interbus reset. */
#define SUPI3_IN1_ADDR                            0x01u
#define SUPI3_IN1_RESET                           0x00u
#define   SUPI3_IN1_DATA_POS                      0u
#define   SUPI3_IN1_DATA_MSK                      0xFFu

/* OUT1: INTERBUS OUT byte 1. Address 1, read (r).
 * Ref: 3.4.8. Cleared by: power-up, interbus reset. */
#define SUPI3_OUT1_ADDR                           0x01u
#define SUPI3_OUT1_RESET                          0x00u
#define   SUPI3_OUT1_DATA_POS                     0u
#define   SUPI3_OUT1_DATA_MSK                     0xFFu

/* IN2: INTERBUS IN byte 2. Address 2, write (w).
 * Ref: 3.4.8. Cleared by: power-up, interbus reset. */
#define SUPI3_IN2_ADDR                            0x02u
#define SUPI3_IN2_RESET                           0x00u
#define   SUPI3_IN2_DATA_POS                      0u
#define   SUPI3_IN2_DATA_MSK                      0xFFu

/* OUT2: INTERBUS OUT byte 2. Address 2, read (r).
 * Ref: 3.4.8. Cleared by: power-up, interbus reset. */
#define SUPI3_OUT2_ADDR                           0x02u
#define SUPI3_OUT2_RESET                          0x00u
#define   SUPI3_OUT2_DATA_POS                     0u
#define   SUPI3_OUT2_DATA_MSK                     0xFFu

/* IN3: INTERBUS IN byte 3. Address 3, write (w).
 * Ref: 3.4.8. Cleared by: power-up, interbus reset. */
#define SUPI3_IN3_ADDR                            0x03u
#define SUPI3_IN3_RESET                           0x00u
#define   SUPI3_IN3_DATA_POS                      0u
#define   SUPI3_IN3_DATA_MSK                      0xFFu

/* OUT3: INTERBUS OUT byte 3. Address 3, read (r).
 * Ref: 3.4.8. Cleared by: power-up, interbus reset. */
#define SUPI3_OUT3_ADDR                           0x03u
#define SUPI3_OUT3_RESET                          0x00u
#define   SUPI3_OUT3_DATA_POS                     0u
#define   SUPI3_OUT3_DATA_MSK                     0xFFu

/* ALARM: Processor alarm register. Address 7, write (w).
 * Ref: 3.4.9. Cleared by: power-up reset. */
#define SUPI3_ALARM_ADDR                          0x07u
#define SUPI3_ALARM_RESET                         0x00u
#define   SUPI3_ALARM_DATA_POS                    0u
#define   SUPI3_ALARM_DATA_MSK                    0xFFu

/* PCMD: Processor command register. Address 7, read (r).
 * Ref: 3.4.9. Cleared by: power-up reset. */
#define SUPI3_PCMD_ADDR                           0x07u
#define SUPI3_PCMD_RESET                          0x00u
#define   SUPI3_PCMD_DATA_POS                     0u
#define   SUPI3_PCMD_DATA_MSK                     0xFFu

/* LENGTH_OUT: Length of the outgoing interface. Address 8, read (r).
 * Ref: 3.4.12, Fig. 3-16, Table 1-5. Cleared by: power-up reset. */
#define SUPI3_LENGTH_OUT_ADDR                     0x08u
#define SUPI3_LENGTH_OUT_RESET                    0x00u
#define   SUPI3_LENGTH_OUT_LENGTH_POS             0u    /* assumption RM-5 */
#define   SUPI3_LENGTH_OUT_LENGTH_MSK             0x3Fu /* assumption RM-5 */
#define   SUPI3_LENGTH_OUT_MEDIUM_POS             6u    /* assumption RM-5 */
#define   SUPI3_LENGTH_OUT_MEDIUM_MSK             0x40u /* assumption RM-5 */
#define   SUPI3_LENGTH_OUT_MEDIUM_POLYMER         0x00u /* assumption RM-5 */
#define   SUPI3_LENGTH_OUT_MEDIUM_GLASS           0x40u /* assumption RM-5 */
#define   SUPI3_LENGTH_OUT_ENABLE_POS             7u    /* assumption RM-5 */
#define   SUPI3_LENGTH_OUT_ENABLE_MSK             0x80u /* assumption RM-5 */

/* LENGTH_BRANCH: Length of the bus branch. Address 9, read (r).
 * Ref: 3.4.12, Fig. 3-16, Table 1-5. Cleared by: power-up reset. */
#define SUPI3_LENGTH_BRANCH_ADDR                  0x09u
#define SUPI3_LENGTH_BRANCH_RESET                 0x00u
#define   SUPI3_LENGTH_BRANCH_LENGTH_POS          0u    /* assumption RM-5 */
#define   SUPI3_LENGTH_BRANCH_LENGTH_MSK          0x3Fu /* assumption RM-5 */
#define   SUPI3_LENGTH_BRANCH_MEDIUM_POS          6u    /* assumption RM-5 */
#define   SUPI3_LENGTH_BRANCH_MEDIUM_MSK          0x40u /* assumption RM-5 */
#define   SUPI3_LENGTH_BRANCH_MEDIUM_POLYMER      0x00u /* assumption RM-5 */
#define   SUPI3_LENGTH_BRANCH_MEDIUM_GLASS        0x40u /* assumption RM-5 */
#define   SUPI3_LENGTH_BRANCH_ENABLE_POS          7u    /* assumption RM-5 */
#define   SUPI3_LENGTH_BRANCH_ENABLE_MSK          0x80u /* assumption RM-5 */

/* POWER_IN: Power level of the incoming interface, enable. Address 10, read (r).
 * Ref: 3.4.13, Fig. 3-17. Cleared by: power-up reset. */
#define SUPI3_POWER_IN_ADDR                       0x0Au
#define SUPI3_POWER_IN_RESET                      0x00u
#define   SUPI3_POWER_IN_LEVEL_POS                0u    /* assumption RM-6 */
#define   SUPI3_POWER_IN_LEVEL_MSK                0x0Fu /* assumption RM-6 */
#define   SUPI3_POWER_IN_ENABLE_POS               7u    /* assumption RM-6 */
#define   SUPI3_POWER_IN_ENABLE_MSK               0x80u /* assumption RM-6 */

/* POWER_OUT_BRANCH: Power level of the branch and the outgoing interface. Address 11, read (r).
 * Ref: 3.4.13, Fig. 3-18. Cleared by: power-up reset. */
#define SUPI3_POWER_OUT_BRANCH_ADDR               0x0Bu
#define SUPI3_POWER_OUT_BRANCH_RESET              0x00u
#define   SUPI3_POWER_OUT_BRANCH_OUT_LEVEL_POS    0u    /* assumption RM-6 */
#define   SUPI3_POWER_OUT_BRANCH_OUT_LEVEL_MSK    0x0Fu /* assumption RM-6 */
#define   SUPI3_POWER_OUT_BRANCH_BRANCH_LEVEL_POS 4u    /* assumption RM-6 */
#define   SUPI3_POWER_OUT_BRANCH_BRANCH_LEVEL_MSK 0xF0u /* assumption RM-6 */

/* ID: ID code. Address 12, write (w), read (r).
 * Ref: 3.4.10, 3.4.3, Table A-3. Cleared by: power-up reset. */
#define SUPI3_ID_ADDR                             0x0Cu
#define SUPI3_ID_RESET                            0x00u
#define   SUPI3_ID_CODE_POS                       0u
#define   SUPI3_ID_CODE_MSK                       0xFFu

/* SET: SET register. Address 13, write (w), read (r).
 * Ref: 3.4.11, Figs. 3-14 and 3-15, Tables 3-11 and 3-12. Cleared by: power-up reset. */
#define SUPI3_SET_ADDR                            0x0Du
#define SUPI3_SET_RESET                           0x00u
#define   SUPI3_SET_PCP_N_POS                     7u    /* assumption RM-4 */
#define   SUPI3_SET_PCP_N_MSK                     0x80u /* assumption RM-4 */
#define   SUPI3_SET_EXTREG_POS                    6u    /* assumption RM-4 */
#define   SUPI3_SET_EXTREG_MSK                    0x40u /* assumption RM-4 */
#define   SUPI3_SET_LENGTH_CODE_POS               0u    /* assumption RM-4 */
#define   SUPI3_SET_LENGTH_CODE_MSK               0x1Fu /* assumption RM-4 */
#define   SUPI3_SET_CL_POS                        0u    /* assumption RM-4 */
#define   SUPI3_SET_CL_MSK                        0x07u /* assumption RM-4 */
#define   SUPI3_SET_CL_LEN_0_BITS                 0x00u /* assumption RM-4 */
#define   SUPI3_SET_CL_LEN_4_BITS                 0x01u /* assumption RM-4 */
#define   SUPI3_SET_CL_LEN_1_BYTE                 0x02u /* assumption RM-4 */
#define   SUPI3_SET_CL_LEN_1_WORD                 0x03u /* assumption RM-4 */
#define   SUPI3_SET_CL_LEN_3_BYTES                0x04u /* assumption RM-4 */
#define   SUPI3_SET_CL_LEN_2_WORDS                0x05u /* assumption RM-4 */

/* IRQ_EN: Interrupt enable. Address 14, write (w).
 * Ref: 3.4.14, Fig. 3-19, Table 3-13. Cleared by: power-up reset. */
#define SUPI3_IRQ_EN_ADDR                         0x0Eu
#define SUPI3_IRQ_EN_RESET                        0x00u
#define   SUPI3_IRQ_EN_PCMD_POS                   6u    /* assumption RM-7 */
#define   SUPI3_IRQ_EN_PCMD_MSK                   0x40u /* assumption RM-7 */
#define   SUPI3_IRQ_EN_INVALID_POS                5u    /* assumption RM-7 */
#define   SUPI3_IRQ_EN_INVALID_MSK                0x20u /* assumption RM-7 */
#define   SUPI3_IRQ_EN_VALID_POS                  4u    /* assumption RM-7 */
#define   SUPI3_IRQ_EN_VALID_MSK                  0x10u /* assumption RM-7 */
#define   SUPI3_IRQ_EN_ID_CYCLE_POS               3u    /* assumption RM-7 */
#define   SUPI3_IRQ_EN_ID_CYCLE_MSK               0x08u /* assumption RM-7 */
#define   SUPI3_IRQ_EN_IB_RESET_POS               2u    /* assumption RM-7 */
#define   SUPI3_IRQ_EN_IB_RESET_MSK               0x04u /* assumption RM-7 */
#define   SUPI3_IRQ_EN_PCP_RX_POS                 1u    /* assumption RM-7 */
#define   SUPI3_IRQ_EN_PCP_RX_MSK                 0x02u /* assumption RM-7 */
#define   SUPI3_IRQ_EN_PCP_TX_POS                 0u    /* assumption RM-7 */
#define   SUPI3_IRQ_EN_PCP_TX_MSK                 0x01u /* assumption RM-7 */

/* IRQ_EVT: Interrupt event. Address 14, read (rc).
 * Ref: 3.4.14, Fig. 3-20, Table 3-13. Cleared by: power-up reset. */
#define SUPI3_IRQ_EVT_ADDR                        0x0Eu
#define SUPI3_IRQ_EVT_RESET                       0x00u
#define SUPI3_IRQ_EVT_CLEAR_ON_READ_MSK           0x7Fu /* assumptions RM-7, RM-8 */
#define   SUPI3_IRQ_EVT_IO_ACCESS_POS             7u    /* assumptions RM-7, RM-8 */
#define   SUPI3_IRQ_EVT_IO_ACCESS_MSK             0x80u /* assumptions RM-7, RM-8 */
#define   SUPI3_IRQ_EVT_PCMD_POS                  6u    /* assumption RM-7 */
#define   SUPI3_IRQ_EVT_PCMD_MSK                  0x40u /* assumption RM-7 */
#define   SUPI3_IRQ_EVT_INVALID_POS               5u    /* assumption RM-7 */
#define   SUPI3_IRQ_EVT_INVALID_MSK               0x20u /* assumption RM-7 */
#define   SUPI3_IRQ_EVT_VALID_POS                 4u    /* assumption RM-7 */
#define   SUPI3_IRQ_EVT_VALID_MSK                 0x10u /* assumption RM-7 */
#define   SUPI3_IRQ_EVT_ID_CYCLE_POS              3u    /* assumption RM-7 */
#define   SUPI3_IRQ_EVT_ID_CYCLE_MSK              0x08u /* assumption RM-7 */
#define   SUPI3_IRQ_EVT_IB_RESET_POS              2u    /* assumption RM-7 */
#define   SUPI3_IRQ_EVT_IB_RESET_MSK              0x04u /* assumption RM-7 */
#define   SUPI3_IRQ_EVT_PCP_RX_POS                1u    /* assumption RM-7 */
#define   SUPI3_IRQ_EVT_PCP_RX_MSK                0x02u /* assumption RM-7 */
#define   SUPI3_IRQ_EVT_PCP_TX_POS                0u    /* assumption RM-7 */
#define   SUPI3_IRQ_EVT_PCP_TX_MSK                0x01u /* assumption RM-7 */

#endif /* SUPI3_REGS_H */
