// Test helper: writes small OpenVDB files whose densities have analytic
// answers (tests/reference/test_fog.c). Not part of libstrahl.
#include "vdb_writer.h"

#include <exception>
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>

extern "C" bool st_test_write_vdb(const char *path, const st_test_vdb *spec) {
    try {
        openvdb::initialize();
        openvdb::GridPtrVec grids;
        const openvdb::math::Transform::Ptr xf =
            openvdb::math::Transform::createLinearTransform(spec->voxel);
        if (spec->vector_grid) {
            openvdb::Vec3SGrid::Ptr g = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
            g->setName(spec->name);
            g->setTransform(xf);
            g->tree().setValue(openvdb::Coord(0, 0, 0), openvdb::Vec3s(spec->value));
            grids.push_back(g);
        } else {
            openvdb::FloatGrid::Ptr g = openvdb::FloatGrid::create(spec->background);
            g->setName(spec->name);
            g->setTransform(xf);
            auto acc = g->getAccessor();
            for (int k = 0; k < spec->n[2]; k++)
                for (int j = 0; j < spec->n[1]; j++)
                    for (int i = 0; i < spec->n[0]; i++) {
                        float v = spec->value;
                        if (spec->radius > 0) {
                            double x = i - 0.5 * (spec->n[0] - 1), y = j - 0.5 * (spec->n[1] - 1),
                                   z = k - 0.5 * (spec->n[2] - 1);
                            double q = (x * x + y * y + z * z) / (spec->radius * spec->radius);
                            v = q < 1.0 ? (float)(spec->value * (1.0 - q)) : 0.0f;
                        }
                        acc.setValue(openvdb::Coord(spec->origin[0] + i, spec->origin[1] + j,
                                                    spec->origin[2] + k),
                                     v);
                    }
            if (spec->has_bad)
                acc.setValue(openvdb::Coord(spec->bad[0], spec->bad[1], spec->bad[2]),
                             spec->bad_value);
            grids.push_back(g);
        }
        // A second grid, so a wrong name has something to list.
        if (!spec->single_grid) {
            openvdb::FloatGrid::Ptr t = openvdb::FloatGrid::create(0.0f);
            t->setName("temperature");
            t->tree().setValue(openvdb::Coord(0, 0, 0), 1.0f);
            grids.push_back(t);
        }
        openvdb::io::File file(path);
        file.write(grids);
        file.close();
        return true;
    } catch (const std::exception &) {
        return false;
    }
}
