// False-colour images with their legend, shared by `compare --heatmap` and
// `convert --false-colour`: values divided by a scale go through the heat
// ramp (st_heat_colour: black, blue, red, yellow, white), and a strip below
// the picture holds the colour bar with its values drawn in. The scale and
// what the values are go into the PNG's tEXt chunks, so two maps can be
// told apart and compared without guessing.
#ifndef ST_FALSE_COLOUR_H
#define ST_FALSE_COLOUR_H
#include "st_base.h"

// Rows the legend adds below the picture, and the least width of the output
// (a narrower picture is padded on the right so the labels fit).
#define ST_LEGEND_ROWS 24
#define ST_LEGEND_MIN_WIDTH 96

typedef struct st_false_colour {
    const char *quantity; // what the values are ("mean over R,G,B of |A - B|")
    double scale;         // the value drawn white, the top of the bar; > 0 and finite
} st_false_colour;

// Largest finite value of v[0, n) (0 when there is none).
double st_false_colour_max(const double *v, size_t n);
// Writes v (w x h values, top row first, finite) as an 8-bit RGB PNG of
// max(w, ST_LEGEND_MIN_WIDTH) x (h + ST_LEGEND_ROWS), atomically. Values
// above the scale are white (their count is in the metadata), below 0 black.
bool st_write_false_colour(const char *path, const double *v, int w, int h,
                           const st_false_colour *fc, st_err *err);

#endif
