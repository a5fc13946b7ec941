/* The lighting and display model shared by the simplifier (which predicts contrast from vertex
 * intensities) and the renderer (which draws them): Gouraud shading of a Lambertian surface under
 * one directional light plus ambient, computed in linear light per vertex, shown on a display
 * with a gamma-2.2 response between a black level and a peak luminance. Keeping both sides on one
 * model is what makes the predicted contrast the contrast the images show. */
#ifndef LOD_SHADE_H
#define LOD_SHADE_H

#define LOD_PI 3.14159265358979323846

typedef struct {
    float light_dir[3];   /* unit, world space, towards the light */
    float albedo;         /* 0..1 */
    float ambient;        /* share of the light that is ambient, 0..1 */
    float background;     /* linear intensity of the background, 0..1 */
    double lum_peak_cdm2; /* luminance of pixel value 255 */
    double lum_black_cdm2;/* luminance of pixel value 0 */
} lod_shade;

/* linear intensity of a vertex with unit normal n */
static inline float lod_shade_intensity(const lod_shade *s, const float n[3])
{
    float d = n[0] * s->light_dir[0] + n[1] * s->light_dir[1] + n[2] * s->light_dir[2];
    return s->albedo * (s->ambient + (1 - s->ambient) * (d > 0 ? d : 0));
}

/* luminance (cd/m2) the display shows for linear intensity i */
static inline double lod_shade_lum(const lod_shade *s, double i)
{
    return s->lum_black_cdm2 + (s->lum_peak_cdm2 - s->lum_black_cdm2) * i;
}

#endif
