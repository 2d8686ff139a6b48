/* Linkage of the native FMU's internal functions and friction elements. The binaries
 * are compiled from the generated sources/drymount_fmu.c, which defines
 * DRYMOUNT_UNITY and #includes every other .c file: one translation unit in which
 * every internal function (ml_*, md_*, in_*) and element (ml_jenkins, ...) is static,
 * so an importer can compile two of these FMUs (with different FMI2_FUNCTION_PREFIX /
 * FMI3_FUNCTION_PREFIX) into one program. Compiled file by file (DRYMOUNT_UNITY not
 * defined), the same sources link as usual. */
#ifndef DRYMOUNT_INTERNAL_H
#define DRYMOUNT_INTERNAL_H

#if defined(DRYMOUNT_UNITY) && defined(__GNUC__)
/* prototypes of internal functions (some are unused by one FMI version's glue) */
#define ML_DECL static __attribute__((unused))
#define ML_ELEMENT_DECL static
#define ML_ELEMENT_DEF static
#elif defined(DRYMOUNT_UNITY)
#define ML_DECL static         /* prototypes of internal functions */
#define ML_ELEMENT_DECL static /* a friction element's declaration (friction_table.h) */
#define ML_ELEMENT_DEF static  /* ... and its definition (<element>.c) */
#else
#define ML_DECL
#define ML_ELEMENT_DECL extern
#define ML_ELEMENT_DEF
#endif

#endif
