// The structure OpenVDB reads before any voxel (st_vdb_header.c): checked
// against the file's size first, so that no length field of a corrupt file
// makes OpenVDB allocate (and fill) gigabytes for a string or a metadata
// value. Internal to st_vdb.cpp.
#ifndef ST_VDB_HEADER_H
#define ST_VDB_HEADER_H
#include "st_base.h"

#ifdef __cplusplus
extern "C" {
#endif

// Walks the header, the file's metadata, the grid descriptors and, for each
// grid, its compression flags, metadata and transform's map name, in fd of
// `size` bytes (pread, the offset is left alone). False with an ST_ERR_INPUT
// message naming path and what is wrong: a length or an offset beyond the
// end of the file, a version strahl's OpenVDB does not read.
bool st_vdb_check_header(int fd, uint64_t size, const char *path, st_err *err);

#ifdef __cplusplus
}
#endif
#endif
