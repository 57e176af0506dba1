#include "st_list.h"
#include <string.h>

const char *st_list_next(const char *p, char out[ST_NAME_MAX], bool *optional) {
    while (p && (*p == ' ' || *p == ','))
        p++;
    if (!p || !*p) return NULL;
    const char *e = p;
    while (*e && *e != ',')
        e++;
    const char *t = e;
    while (t > p && t[-1] == ' ')
        t--;
    bool opt = t > p && t[-1] == '?';
    if (opt) t--;
    size_t n = (size_t)(t - p) < ST_NAME_MAX ? (size_t)(t - p) : ST_NAME_MAX - 1;
    memcpy(out, p, n);
    out[n] = 0;
    if (optional) *optional = opt;
    return e;
}

bool st_list_has(const char *list, const char *name) {
    char tok[ST_NAME_MAX];
    for (const char *p = list; (p = st_list_next(p, tok, NULL));)
        if (!strcmp(tok, name)) return true;
    return false;
}
