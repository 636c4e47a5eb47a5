/** @file
 *  @brief Preprocessor helpers: VSD_PP_FOR_EACH(macro, data, args...) for up to 32 arguments.
 */
#pragma once

#define VSD_PP_CAT_(a, b) a##b
#define VSD_PP_CAT(a, b) VSD_PP_CAT_(a, b)
#define VSD_PP_NARG(...)                                                                                    \
  VSD_PP_NARG_(__VA_ARGS__, 32, 31, 30, 29, 28, 27, 26, 25, 24, 23, 22, 21, 20, 19, 18, 17, 16, 15, 14, 13, \
               12, 11, 10, 9, 8, 7, 6, 5, 4, 3, 2, 1, 0)
#define VSD_PP_NARG_(_1, _2, _3, _4, _5, _6, _7, _8, _9, _10, _11, _12, _13, _14, _15, _16, _17, _18, _19, \
                     _20, _21, _22, _23, _24, _25, _26, _27, _28, _29, _30, _31, _32, N, ...)              \
  N

#define VSD_PP_FE_1(m, d, x) m(d, x)
#define VSD_PP_FE_2(m, d, x, ...) m(d, x) VSD_PP_FE_1(m, d, __VA_ARGS__)
#define VSD_PP_FE_3(m, d, x, ...) m(d, x) VSD_PP_FE_2(m, d, __VA_ARGS__)
#define VSD_PP_FE_4(m, d, x, ...) m(d, x) VSD_PP_FE_3(m, d, __VA_ARGS__)
#define VSD_PP_FE_5(m, d, x, ...) m(d, x) VSD_PP_FE_4(m, d, __VA_ARGS__)
#define VSD_PP_FE_6(m, d, x, ...) m(d, x) VSD_PP_FE_5(m, d, __VA_ARGS__)
#define VSD_PP_FE_7(m, d, x, ...) m(d, x) VSD_PP_FE_6(m, d, __VA_ARGS__)
#define VSD_PP_FE_8(m, d, x, ...) m(d, x) VSD_PP_FE_7(m, d, __VA_ARGS__)
#define VSD_PP_FE_9(m, d, x, ...) m(d, x) VSD_PP_FE_8(m, d, __VA_ARGS__)
#define VSD_PP_FE_10(m, d, x, ...) m(d, x) VSD_PP_FE_9(m, d, __VA_ARGS__)
#define VSD_PP_FE_11(m, d, x, ...) m(d, x) VSD_PP_FE_10(m, d, __VA_ARGS__)
#define VSD_PP_FE_12(m, d, x, ...) m(d, x) VSD_PP_FE_11(m, d, __VA_ARGS__)
#define VSD_PP_FE_13(m, d, x, ...) m(d, x) VSD_PP_FE_12(m, d, __VA_ARGS__)
#define VSD_PP_FE_14(m, d, x, ...) m(d, x) VSD_PP_FE_13(m, d, __VA_ARGS__)
#define VSD_PP_FE_15(m, d, x, ...) m(d, x) VSD_PP_FE_14(m, d, __VA_ARGS__)
#define VSD_PP_FE_16(m, d, x, ...) m(d, x) VSD_PP_FE_15(m, d, __VA_ARGS__)
#define VSD_PP_FE_17(m, d, x, ...) m(d, x) VSD_PP_FE_16(m, d, __VA_ARGS__)
#define VSD_PP_FE_18(m, d, x, ...) m(d, x) VSD_PP_FE_17(m, d, __VA_ARGS__)
#define VSD_PP_FE_19(m, d, x, ...) m(d, x) VSD_PP_FE_18(m, d, __VA_ARGS__)
#define VSD_PP_FE_20(m, d, x, ...) m(d, x) VSD_PP_FE_19(m, d, __VA_ARGS__)
#define VSD_PP_FE_21(m, d, x, ...) m(d, x) VSD_PP_FE_20(m, d, __VA_ARGS__)
#define VSD_PP_FE_22(m, d, x, ...) m(d, x) VSD_PP_FE_21(m, d, __VA_ARGS__)
#define VSD_PP_FE_23(m, d, x, ...) m(d, x) VSD_PP_FE_22(m, d, __VA_ARGS__)
#define VSD_PP_FE_24(m, d, x, ...) m(d, x) VSD_PP_FE_23(m, d, __VA_ARGS__)
#define VSD_PP_FE_25(m, d, x, ...) m(d, x) VSD_PP_FE_24(m, d, __VA_ARGS__)
#define VSD_PP_FE_26(m, d, x, ...) m(d, x) VSD_PP_FE_25(m, d, __VA_ARGS__)
#define VSD_PP_FE_27(m, d, x, ...) m(d, x) VSD_PP_FE_26(m, d, __VA_ARGS__)
#define VSD_PP_FE_28(m, d, x, ...) m(d, x) VSD_PP_FE_27(m, d, __VA_ARGS__)
#define VSD_PP_FE_29(m, d, x, ...) m(d, x) VSD_PP_FE_28(m, d, __VA_ARGS__)
#define VSD_PP_FE_30(m, d, x, ...) m(d, x) VSD_PP_FE_29(m, d, __VA_ARGS__)
#define VSD_PP_FE_31(m, d, x, ...) m(d, x) VSD_PP_FE_30(m, d, __VA_ARGS__)
#define VSD_PP_FE_32(m, d, x, ...) m(d, x) VSD_PP_FE_31(m, d, __VA_ARGS__)

/// @brief Expands `m(d, x)` for each `x` of the arguments.
#define VSD_PP_FOR_EACH(m, d, ...) VSD_PP_CAT(VSD_PP_FE_, VSD_PP_NARG(__VA_ARGS__))(m, d, __VA_ARGS__)
