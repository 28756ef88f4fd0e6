/*
 * How long must the robot touch to tell e = 35,000 from e = 20,000
 * (J s^-1/2 K^-1 m^-2) with a sensor noise of 0.05 degC and the sensor 10 degC
 * above the object? Answered from a designkit lookup table exported as a C99
 * header (see README.md; `make` writes designkit_table.h and builds ./lookup).
 *
 *   ./lookup                      the question above
 *   ./lookup E1 E2 NOISE DT       the same question for other numbers
 *   ./lookup --batch < queries    one query per line, one answer per line:
 *       min_contact E1 E2 NOISE DT
 *       delta_e E NOISE DT CONTACT          (also delta_e_lower, delta_e_upper)
 *       distinguishable E1 E2 NOISE DT CONTACT
 *     answers are printed with %.9g; the header's sentinels pass through
 *     (-1 nothing suffices, -2 outside the table's grid, -3 invalid input).
 *
 * Only the header and libm are needed: the same code builds for a microcontroller.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "designkit_table.h"

static void explain(float e1, float e2, float noise_c, float delta_t_c)
{
    float t = designkit_min_contact_s(e1, e2, noise_c, delta_t_c);

    printf("table %s (%s fidelity, F1 >= %g, sensor %s), %s\n", DESIGNKIT_SOURCE_TABLE, DESIGNKIT_FIDELITY,
           DESIGNKIT_THRESHOLD, DESIGNKIT_SENSOR_NAME, DESIGNKIT_SOURCE_HASH);
    printf("separate e = %g from e = %g J s^-1/2 K^-1 m^-2, noise %g degC, dT %g degC:\n", e1, e2, noise_c,
           delta_t_c);
    if (t == DESIGNKIT_NONE) {
        printf("  no tabulated contact time up to %g s separates them: heat the sensor more or lower the noise\n",
               DESIGNKIT_CONTACT_MAX_S);
        return;
    }
    if (t == DESIGNKIT_OUTSIDE) {
        printf("  outside this table's grid (no extrapolation): export a table that covers it\n");
        return;
    }
    if (t == DESIGNKIT_INVALID) {
        printf("  invalid input (effusivities must be positive and different, noise >= 0, dT != 0)\n");
        return;
    }
    printf("  touch for at least %.3f s\n", t);
    {
        /* the robot's controller runs at 100 Hz: round the contact time up to its period */
        float contact = (float)ceil(t * 100.0f) / 100.0f;
        float lo = e1 < e2 ? e1 : e2, hi = e1 < e2 ? e2 : e1;
        int yes = designkit_distinguishable(e1, e2, noise_c, delta_t_c, contact);
        printf("  touching for %.2f s (rounded up to the 10 ms control period) separates them: %s\n", contact,
               yes == DESIGNKIT_YES ? "yes" : "no");
        printf("  delta(e) at %.2f s: %.0f upwards from %g, %.0f downwards from %g (their distance: %g)\n",
               contact, designkit_delta_e_upper(lo, noise_c, delta_t_c, contact), lo,
               designkit_delta_e_lower(hi, noise_c, delta_t_c, contact), hi, hi - lo);
    }
}

static int batch(void)
{
    char line[512], op[64];
    float a[5];
    int bad = 0;

    while (fgets(line, sizeof line, stdin)) {
        int n = sscanf(line, "%63s %f %f %f %f %f", op, &a[0], &a[1], &a[2], &a[3], &a[4]);
        if (n <= 0) continue;
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
        explain(strtof(argv[1], NULL), strtof(argv[2], NULL), strtof(argv[3], NULL), strtof(argv[4], NULL));
        return 0;
    }
    if (argc != 1) {
        fprintf(stderr, "usage: %s [E1 E2 NOISE_C DELTA_T_C] | --batch < queries\n", argv[0]);
        return 2;
    }
    explain(35000.0f, 20000.0f, 0.05f, 10.0f);
    return 0;
}
