/* The examples' error check: CHECK(call) prints a failed call, its status and the library's
 * message, and exits. */

#ifndef SOFTSHADOW_EXAMPLE_CHECK_H
#define SOFTSHADOW_EXAMPLE_CHECK_H

#include <stdio.h>
#include <stdlib.h>

#include "softshadow.h"

/* Any failure: print the call, its status and the library's message, and stop. */
#define CHECK(call)                                                                       \
    do {                                                                                  \
        softshadow_status status_ = (call);                                               \
        if (status_ != SOFTSHADOW_OK) {                                                   \
            char message_[512];                                                           \
            softshadow_last_error(message_, sizeof message_);                             \
            fprintf(stderr, "%s failed with status %d: %s\n", #call, (int)status_, message_); \
            exit(1);                                                                      \
        }                                                                                 \
    } while (0)

#endif
