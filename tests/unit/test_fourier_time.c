/* neural/fourier_time.h: Neu-PiG's time features, the sines then the
 * cosines of 2^j π t. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include "neural/fourier_time.h"
#include "testutil.h"

static void test_values(void **state)
{
    (void)state;
    const double ts[] = {0.0, 0.3, 0.5, 1.0};
    for (int n = 0; n < 4; n++) {
        float out[8];
        tcb_fourier_time(ts[n], 4, out);
        double f = 1.0;
        for (int j = 0; j < 4; j++, f *= 2.0) {
            assert_near(out[j], sin(f * M_PI * ts[n]), 1e-7);
            assert_near(out[4 + j], cos(f * M_PI * ts[n]), 1e-7);
        }
    }
    float mid[8];
    tcb_fourier_time(0.5, 4, mid); /* sin(π/2) = 1, cos(π/2) = 0, sin(π) = 0, cos(π) = −1 */
    assert_near(mid[0], 1.0, 1e-7);
    assert_near(mid[4], 0.0, 1e-7);
    assert_near(mid[5], -1.0, 1e-7);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_values)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
