/*
 * volpack_bench: renders VolPack's example MRI head (brainsmall.den, 128x128x84) with
 * VolPack's classified shear-warp renderer, classified and shaded as VolPack's own example
 * (examples/rendervolume.c: density ramp 0:0,24:1,255:1, gradient ramp 0:0,5:0,20:1,221:1,
 * minimum voxel opacity 0.05, ray opacity 0.95, material 0.18/0.35/0.39/10, light
 * (0.3,0.3,1), a 7,924-entry shading table, view rotated 130 degrees about y and -15 about
 * x), without depth cueing (rmapgen has none). Prints one line per size:
 *   volpack SIZE MEDIAN_MS MIN_MS
 * The frame is what changes per frame in a preview: the shading table and the render of the
 * classified volume (classification is done once, before timing, like rmapgen's gradients).
 * Usage: volpack_bench DEN_FILE REPEAT SIZE... [-ppm PREFIX]
 * Built and run by scripts/bench-volume.sh (make bench-volume).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <volpack.h>

#define XLEN 128
#define YLEN 128
#define ZLEN 84
#define HEADER 62 /* bytes of .den header */

typedef struct {
    short normal;
    unsigned char density;
    unsigned char gradient;
} RawVoxel;

static double now_ms(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec * 1e3 + t.tv_nsec / 1e6;
}

static int cmp(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static void check(vpContext *vpc, vpResult r, const char *what) {
    if (r != VP_OK) {
        fprintf(stderr, "volpack_bench: %s: %s\n", what, vpGetErrorString(vpGetError(vpc)));
        exit(1);
    }
}

int main(int argc, char **argv) {
    if (argc < 4) {
        fprintf(stderr, "usage: volpack_bench DEN_FILE REPEAT SIZE... [-ppm PREFIX]\n");
        return 2;
    }
    const char *ppm = NULL;
    int nsizes = 0, sizes[16];
    for (int i = 3; i < argc; i++) {
        if (!strcmp(argv[i], "-ppm") && i + 1 < argc) {
            ppm = argv[++i];
        } else if (nsizes < 16 && atoi(argv[i]) > 0 && atoi(argv[i]) <= 4096) {
            sizes[nsizes++] = atoi(argv[i]);
        } else {
            fprintf(stderr, "volpack_bench: bad size '%s' (1..4096)\n", argv[i]);
            return 2;
        }
    }
    int repeat = atoi(argv[2]);
    if (repeat < 1 || repeat > 1000) {
        fprintf(stderr, "volpack_bench: repeat %s must be in 1..1000\n", argv[2]);
        return 2;
    }
    size_t n = (size_t)XLEN * YLEN * ZLEN;
    unsigned char *density = malloc(n);
    RawVoxel *volume = malloc(n * sizeof(RawVoxel));
    FILE *f = fopen(argv[1], "rb");
    if (!density || !volume || !f || fseek(f, HEADER, SEEK_SET) != 0 ||
        fread(density, 1, n, f) != n) {
        fprintf(stderr, "volpack_bench: cannot read %zu voxels after a %d-byte header from %s\n",
                n, HEADER, argv[1]);
        return 1;
    }
    fclose(f);

    vpContext *vpc = vpCreateContext();
    RawVoxel *dummy = NULL;
    vpSetVolumeSize(vpc, XLEN, YLEN, ZLEN);
    vpSetVoxelSize(vpc, sizeof(RawVoxel), 3, 2, 2);
    vpSetVoxelField(vpc, 0, sizeof(short), vpFieldOffset(dummy, normal), VP_NORM_MAX);
    vpSetVoxelField(vpc, 1, 1, vpFieldOffset(dummy, density), 255);
    vpSetVoxelField(vpc, 2, 1, vpFieldOffset(dummy, gradient), VP_GRAD_MAX);
    vpSetRawVoxels(vpc, volume, n * sizeof(RawVoxel), sizeof(RawVoxel),
                   XLEN * sizeof(RawVoxel), XLEN * YLEN * sizeof(RawVoxel));
    check(vpc, vpVolumeNormals(vpc, density, n, 1, 2, 0), "normals");

    static float density_ramp[256], gradient_ramp[VP_GRAD_MAX + 1];
    int dx[] = {0, 24, 255};
    float dy[] = {0.0, 1.0, 1.0};
    int gx[] = {0, 5, 20, 221};
    float gy[] = {0.0, 0.0, 1.0, 1.0};
    vpRamp(density_ramp, sizeof(float), 3, dx, dy);
    vpSetClassifierTable(vpc, 0, 1, density_ramp, sizeof(density_ramp));
    vpRamp(gradient_ramp, sizeof(float), 4, gx, gy);
    vpSetClassifierTable(vpc, 1, 2, gradient_ramp, sizeof(gradient_ramp));
    vpSetd(vpc, VP_MIN_VOXEL_OPACITY, 0.05);
    check(vpc, vpClassifyVolume(vpc), "classify");

    static float shade_table[VP_NORM_MAX + 1];
    vpSetLookupShader(vpc, 1, 1, 0, shade_table, sizeof(shade_table), 0, NULL, 0);
    vpSetMaterial(vpc, VP_MATERIAL0, VP_AMBIENT, VP_BOTH_SIDES, 0.18, 0.18, 0.18);
    vpSetMaterial(vpc, VP_MATERIAL0, VP_DIFFUSE, VP_BOTH_SIDES, 0.35, 0.35, 0.35);
    vpSetMaterial(vpc, VP_MATERIAL0, VP_SPECULAR, VP_BOTH_SIDES, 0.39, 0.39, 0.39);
    vpSetMaterial(vpc, VP_MATERIAL0, VP_SHINYNESS, VP_BOTH_SIDES, 10.0, 0.0, 0.0);
    vpSetLight(vpc, VP_LIGHT0, VP_DIRECTION, 0.3, 0.3, 1.0);
    vpSetLight(vpc, VP_LIGHT0, VP_COLOR, 1.0, 1.0, 1.0);
    vpEnable(vpc, VP_LIGHT0, 1);
    vpSeti(vpc, VP_CONCAT_MODE, VP_CONCAT_LEFT);
    vpCurrentMatrix(vpc, VP_MODEL);
    vpIdentityMatrix(vpc);
    vpRotate(vpc, VP_Y_AXIS, 130.0);
    vpRotate(vpc, VP_X_AXIS, -15.0);
    vpCurrentMatrix(vpc, VP_PROJECT);
    vpIdentityMatrix(vpc);
    vpWindow(vpc, VP_PARALLEL, -0.5, 0.5, -0.5, 0.5, -0.5, 0.5);
    vpCurrentMatrix(vpc, VP_MODEL);
    vpSetd(vpc, VP_MAX_RAY_OPACITY, 0.95);

    for (int s = 0; s < nsizes; s++) {
        int size = sizes[s];
        unsigned char *image = malloc((size_t)size * size);
        double *t = malloc(sizeof(double) * repeat);
        vpSetImage(vpc, image, size, size, size, VP_LUMINANCE);
        /* One untimed frame: first-touch allocations. */
        check(vpc, vpShadeTable(vpc), "shade table");
        check(vpc, vpRenderClassifiedVolume(vpc), "render");
        for (int r = 0; r < repeat; r++) {
            double t0 = now_ms();
            check(vpc, vpShadeTable(vpc), "shade table");
            check(vpc, vpRenderClassifiedVolume(vpc), "render");
            t[r] = now_ms() - t0;
        }
        qsort(t, repeat, sizeof(double), cmp);
        printf("volpack %d %.3f %.3f\n", size, t[repeat / 2], t[0]);
        if (ppm) {
            char name[600];
            snprintf(name, sizeof name, "%s%d.pgm", ppm, size);
            FILE *o = fopen(name, "wb");
            if (o) {
                fprintf(o, "P5\n%d %d\n255\n", size, size);
                fwrite(image, 1, (size_t)size * size, o);
                fclose(o);
            }
        }
        free(image);
        free(t);
    }
    return 0;
}
