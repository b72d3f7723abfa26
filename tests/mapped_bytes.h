/* The bytes of address space this process has mapped (VmSize), for the tests
 * that limit it to what is mapped; 0 where /proc does not say. A header of
 * its own: test_library_load is no cmocka program. */
#pragma once

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static inline size_t lpi_test_mapped_bytes(void) {
    FILE *f = fopen("/proc/self/status", "r");
    char line[256];
    size_t kib = 0;
    while (f && fgets(line, sizeof line, f))
        if (strncmp(line, "VmSize:", 7) == 0) kib = (size_t)strtoull(line + 7, NULL, 10);
    if (f) fclose(f);
    return kib * 1024;
}
