/*
 * How long must the robot touch to tell e = 35,000 from e = 20,000
 * (J s^-1/2 K^-1 m^-2) with a sensor noise of 0.05 degC and the sensor 10 degC
 * above the object? Answered from a designkit lookup table exported as a C99
 * header (see README.md; `make` writes designkit_table.h and builds ./lookup):
 * the same answer, and the same 90 % interval, as `designkit min-contact`.
 *
 *   ./lookup                      the question above
 *   ./lookup E1 E2 NOISE DT       the same question for other numbers
 *   ./lookup --batch < queries    one query per line, one answer per line:
 *       min_contact E1 E2 NOISE DT
 *       delta_e E NOISE DT CONTACT          (also delta_e_lower, delta_e_upper)
 *       distinguishable E1 E2 NOISE DT CONTACT
 *       grid_min_contact, grid_delta_e, grid_delta_e_lower, grid_delta_e_upper,
 *       grid_distinguishable: the same questions by the table's grid rule alone
 *     answers are printed with %.9g; the header's sentinels pass through
 *     (-1 nothing suffices, -2 outside the table's grid, -3 invalid input,
 *     -4 only designkit answers this table as designkit does).
 *
 * Only the header and libm are needed: the same code builds for a microcontroller.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "designkit_table.h"

static void explain(double e1, double e2, double noise_c, double delta_t_c)
{
    double iv[3];
    int s = designkit_min_contact_interval(e1, e2, noise_c, delta_t_c, iv);

    printf("table %s (%s fidelity, F1 >= %g, sensor %s), %s\n", DESIGNKIT_SOURCE_TABLE, DESIGNKIT_FIDELITY,
           DESIGNKIT_THRESHOLD, DESIGNKIT_SENSOR_NAME, DESIGNKIT_SOURCE_HASH);
    printf("separate e = %g from e = %g J s^-1/2 K^-1 m^-2, noise %g degC, dT %g degC:\n", e1, e2, noise_c,
           delta_t_c);
    if (s == DESIGNKIT_NONE_I) {
        printf("  no tabulated contact time up to %g s separates them: heat the sensor more or lower the noise\n",
               DESIGNKIT_CONTACT_MAX_S);
        return;
    }
    if (s == DESIGNKIT_OUTSIDE_I) {
        printf("  outside this table's grid (no extrapolation): export a table that covers it\n");
        return;
    }
    if (s == DESIGNKIT_INVALID_I) {
        printf("  invalid input (effusivities must be positive and different, noise >= 0, dT != 0)\n");
        return;
    }
    if (s == DESIGNKIT_NEEDS_DESIGNKIT_I) {
        printf("  this table cannot be answered as designkit does outside designkit: ask designkit\n");
        return;
    }
    printf("  touch for at least %.3g s (90%% interval %.3g s to %.3g s)\n", iv[0], iv[1], iv[2]);
    {
        /* the robot's controller runs at 100 Hz: plan on the interval's long end, rounded up to its period */
        double contact = ceil((iv[2] > 0 ? iv[2] : iv[0]) * 100.0 - 1e-9) / 100.0;
        double lo = e1 < e2 ? e1 : e2, hi = e1 < e2 ? e2 : e1;
        int sure, yes = designkit_distinguishable_verdict(e1, e2, noise_c, delta_t_c, contact, &sure);
        printf("  touching for %.2f s (the interval's long end, rounded up to the 10 ms control period) separates "
               "them: %s%s\n", contact, yes == DESIGNKIT_YES ? "yes" : "no", sure ? " (confident)" : "");
        printf("  delta(e) at %.2f s: %.0f upwards from %g, %.0f downwards from %g (their distance: %g)\n",
               contact, designkit_delta_e_upper(lo, noise_c, delta_t_c, contact), lo,
               designkit_delta_e_lower(hi, noise_c, delta_t_c, contact), hi, hi - lo);
    }
}

static int batch(void)
{
    char line[512], op[64];
    double a[5];
    int bad = 0;

    while (fgets(line, sizeof line, stdin)) {
        int n = sscanf(line, "%63s %lf %lf %lf %lf %lf", op, &a[0], &a[1], &a[2], &a[3], &a[4]);
        float f[5];
        int i;
        if (n <= 0) continue;
        for (i = 0; i < 5; i++) f[i] = (float)a[i];
        if (!strcmp(op, "min_contact") && n == 5)
            printf("%.9g\n", designkit_min_contact_s(a[0], a[1], a[2], a[3]));
        else if (!strcmp(op, "delta_e") && n == 5)
            printf("%.9g\n", designkit_delta_e(a[0], a[1], a[2], a[3]));
        else if (!strcmp(op, "delta_e_lower") && n == 5)
            printf("%.9g\n", designkit_delta_e_lower(a[0], a[1], a[2], a[3]));
        else if (!strcmp(op, "delta_e_upper") && n == 5)
            printf("%.9g\n", designkit_delta_e_upper(a[0], a[1], a[2], a[3]));
        else if (!strcmp(op, "distinguishable") && n == 6)
            printf("%d\n", designkit_distinguishable(a[0], a[1], a[2], a[3], a[4]));
        else if (!strcmp(op, "grid_min_contact") && n == 5)
            printf("%.9g\n", designkit_grid_min_contact_s(f[0], f[1], f[2], f[3]));
        else if (!strcmp(op, "grid_delta_e") && n == 5)
            printf("%.9g\n", designkit_grid_delta_e(f[0], f[1], f[2], f[3]));
        else if (!strcmp(op, "grid_delta_e_lower") && n == 5)
            printf("%.9g\n", designkit_grid_delta_e_lower(f[0], f[1], f[2], f[3]));
        else if (!strcmp(op, "grid_delta_e_upper") && n == 5)
            printf("%.9g\n", designkit_grid_delta_e_upper(f[0], f[1], f[2], f[3]));
        else if (!strcmp(op, "grid_distinguishable") && n == 6)
            printf("%d\n", designkit_grid_distinguishable(f[0], f[1], f[2], f[3], f[4]));
        else {
            printf("bad-query\n");
            bad = 1;
        }
    }
    return bad ? 2 : 0;
}

int main(int argc, char **argv)
{
    if (argc == 2 && !strcmp(argv[1], "--batch"))
        return batch();
    if (argc == 5) {
        explain(strtod(argv[1], NULL), strtod(argv[2], NULL), strtod(argv[3], NULL), strtod(argv[4], NULL));
        return 0;
    }
    if (argc != 1) {
        fprintf(stderr, "usage: %s [E1 E2 NOISE_C DELTA_T_C] | --batch < queries\n", argv[0]);
        return 2;
    }
    explain(35000.0, 20000.0, 0.05, 10.0);
    return 0;
}
