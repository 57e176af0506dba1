// strahl (internal): the one tokenizer for comma-separated name lists
// ("a, b,c?"): pass resources, requires/provides.
#ifndef ST_LIST_H
#define ST_LIST_H
#include "st_scene.h"

// Copies the next name of `p` into out (spaces trimmed, at most ST_NAME_MAX - 1
// bytes), sets *optional (may be NULL) for a trailing '?', which is dropped,
// and returns where to go on, or NULL at the end of the list.
const char *st_list_next(const char *p, char out[ST_NAME_MAX], bool *optional);
// Is `name` one of the names in `list` (optional ones included)?
bool st_list_has(const char *list, const char *name);
#endif
