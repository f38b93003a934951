/* Instruction counts of the C interface's attitude navigator calls, measured as the Rust demo
   measures AttitudeNavigator<f32> (firmware/src/bin/demo.rs, bench_nav_stream and
   bench_nav_step): the same stream (the Rust demo's, firmware/src/stream.rs, written as a C
   header by firmware/tools/c_stream.py), the same configuration, the same QEMU plugin
   (firmware/qemu-plugin/icount.c) counting between the same markers, bench_start and
   bench_stop.

   Windows, in order (the plugin numbers them from 0):
   0           empty: the markers' own cost, subtracted from every other window;
   1 .. 2001   every call over the stream from switch-on, one window each: est_attitude_imu for
               IMU sample k, then est_attitude_magnetometer for the field of the same time;
   2002        the zero-rate call at rest (the IMU call that fuses a block's zero rate; the last
               one of the stream, as the Rust demo's nav_imu_block_end) again, on a copy of the
               navigator saved before it.

   Output (semihosting): `c_bench_tags <first window> <codes>` (i: IMU call, m: magnetometer
   call), `c_bench <window> <name>`, the final estimate's quaternion as f32 bits and the
   counters, then PASS or FAIL. firmware/tools/c_icount.py reads it with the plugin's counts
   and compares them with the Rust demo's. Run by .ci/c.sh. */
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "ahrs_stream.h"
#include "estimator.h"
#include "semihosting.h"

/* ---- the markers (the plugin's start= and stop= addresses) ---- */

__attribute__((noinline, used)) void bench_start(void) {
    __asm__ volatile("nop");
}

__attribute__((noinline, used)) void bench_stop(void) {
    __asm__ volatile("nop\n\tnop");
}

typedef union {
    unsigned char bytes[2048];
    uint64_t align;
} storage;

static storage nav_storage, before, saved;

/* ---- output ---- */

static void put(const char *s) {
    semihosting_write(s);
}

static void put_uint(uint32_t u) {
    char buf[12];
    int i = (int)sizeof buf - 1;
    buf[i] = '\0';
    do {
        buf[--i] = (char)('0' + u % 10u);
        u /= 10u;
    } while (u != 0u && i > 0);
    put(&buf[i]);
}

static void put_hex(uint32_t u) {
    char buf[9];
    int i;
    for (i = 7; i >= 0; i--) {
        buf[i] = "0123456789abcdef"[u & 0xFu];
        u >>= 4;
    }
    buf[8] = '\0';
    put(buf);
}

static uint32_t bits(float x) {
    union {
        float f;
        uint32_t u;
    } v;
    v.f = x;
    return v.u;
}

/* A word copy the compiler does not turn into a memcpy call (no C library here). */
static void copy(storage *dst, const storage *src) {
    size_t i;
    for (i = 0; i < sizeof dst->bytes; i++) {
        dst->bytes[i] = src->bytes[i];
        __asm__ volatile("" ::: "memory");
    }
}

/* ---- the windows ---- */

static uint32_t window; /* the next window's number */

static est_error imu_window(est_attitude *nav, uint64_t t_ns, const float *gyro, const float *accel) {
    est_error err;
    bench_start();
    err = est_attitude_imu(nav, t_ns, gyro, accel);
    bench_stop();
    window++;
    return err;
}

static est_error mag_window(est_attitude *nav, uint64_t t_ns, const float *field) {
    est_error err;
    bench_start();
    err = est_attitude_magnetometer(nav, t_ns, field);
    bench_stop();
    window++;
    return err;
}

/* Tags buffered and printed 100 a line, as the Rust demo's bench_tags. */
static char tags[101];
static uint32_t n_tags, tags_first;

static void tag(char c) {
    if (n_tags == 0u) {
        tags_first = window - 1u;
    }
    tags[n_tags++] = c;
    if (n_tags == 100u) {
        tags[n_tags] = '\0';
        put("c_bench_tags ");
        put_uint(tags_first);
        put(" ");
        put(tags);
        put("\n");
        n_tags = 0;
    }
}

int main(void) {
    est_attitude_config cfg;
    est_attitude *nav = NULL, *copy_nav;
    est_attitude_counters c;
    est_attitude_report r;
    est_attitude_estimate e;
    uint32_t k, m = 0, zero_rate = 0, refused = 0, step = UINT32_MAX, step_window = 0;
    uint32_t step_zero_rate = 0;

    if (est_attitude_storage_size() > sizeof nav_storage.bytes ||
        est_attitude_storage_align() > sizeof nav_storage.align) {
        put("FAIL: the navigator's storage is too small\n");
        return 1;
    }
    /* The Rust demo's configuration (scenario::attitude_config): the stream's IMU noise and
       magnetometer, everything else the defaults. */
    est_attitude_config_default(&cfg);
    cfg.gyro_noise_density = AHRS_IMU_NOISE[0];
    cfg.gyro_random_walk = AHRS_IMU_NOISE[1];
    cfg.accel_noise_density = AHRS_IMU_NOISE[2];
    cfg.accel_random_walk = AHRS_IMU_NOISE[3];
    cfg.has_magnetometer = true;
    cfg.magnetometer_sigma = AHRS_MAG_SIGMA;
    cfg.has_magnetometer_reference = true;
    cfg.magnetometer_reference[0] = AHRS_MAG_REFERENCE[0];
    cfg.magnetometer_reference[1] = AHRS_MAG_REFERENCE[1];
    cfg.magnetometer_reference[2] = AHRS_MAG_REFERENCE[2];
    if (est_attitude_init(nav_storage.bytes, sizeof nav_storage.bytes, &cfg, &nav) != EST_OK) {
        put("FAIL: configuration refused\n");
        return 1;
    }

    /* Window 0: empty. */
    bench_start();
    bench_stop();
    window = 1;

    for (k = 0; k < AHRS_IMU_SAMPLES; k++) {
        uint64_t t_ns = AHRS_T0_NS + (uint64_t)k * AHRS_DT_NS;
        copy(&before, &nav_storage);
        if (imu_window(nav, t_ns, &AHRS_IMU[k][0], &AHRS_IMU[k][3]) != EST_OK) {
            refused++;
        }
        tag('i');
        if (est_attitude_get_counters(nav, &c) != EST_OK || est_attitude_get_report(nav, &r) != EST_OK) {
            put("FAIL: no counters or report\n");
            return 1;
        }
        if (r.at_rest && c.zero_rate != zero_rate) {
            /* The call that fused a block's zero rate: keep the navigator from before it. */
            copy(&saved, &before);
            step = k;
            step_window = window - 1u;
            step_zero_rate = c.zero_rate;
        }
        zero_rate = c.zero_rate;
        while (m < AHRS_MAG_SAMPLES && AHRS_MAG_INDEX[m] == k) {
            if (mag_window(nav, t_ns, AHRS_MAG[m]) != EST_OK) {
                refused++;
            }
            tag('m');
            m++;
        }
    }
    if (n_tags != 0u) {
        tags[n_tags] = '\0';
        put("c_bench_tags ");
        put_uint(tags_first);
        put(" ");
        put(tags);
        put("\n");
    }
    put("c_bench_group 1 ");
    put_uint(window - 1u);
    put(" c_nav_stream imu_samples=");
    put_uint(AHRS_IMU_SAMPLES);
    put("\n");

    if (step == UINT32_MAX) {
        put("FAIL: no zero-rate call at rest in the stream\n");
        return 1;
    }
    /* The zero-rate call again, on the copy (the navigator holds no pointer to itself: its
       bytes elsewhere are the same navigator). */
    copy_nav = (est_attitude *)(void *)saved.bytes;
    put("c_bench ");
    put_uint(window);
    put(" c_nav_imu_block_end stream_window=");
    put_uint(step_window);
    put("\n");
    if (imu_window(copy_nav, AHRS_T0_NS + (uint64_t)step * AHRS_DT_NS, &AHRS_IMU[step][0],
                   &AHRS_IMU[step][3]) != EST_OK ||
        est_attitude_get_counters(copy_nav, &c) != EST_OK || c.zero_rate != step_zero_rate) {
        put("FAIL: the zero-rate call on the copy did not fuse the zero rate\n");
        return 1;
    }

    /* The run's end, for c_icount.py to check against the Rust run (the host's f32 result). */
    if (est_attitude_get_estimate(nav, &e) != EST_OK || est_attitude_get_counters(nav, &c) != EST_OK ||
        est_attitude_get_report(nav, &r) != EST_OK) {
        put("FAIL: no estimate at the end of the stream\n");
        return 1;
    }
    put("c_nav_q");
    for (k = 0; k < 4u; k++) {
        put(" ");
        put_hex(bits(e.quaternion[k]));
    }
    put("\nc_nav_fused ");
    put_uint(c.gravity_fused + c.heading_fused + c.zero_rate);
    put("\nc_nav_refused ");
    put_uint(refused);
    put("\n");
    if (refused == 0u && r.tilt.valid && r.heading.valid) {
        put("PASS: every sample taken, tilt and heading valid at the end\n");
        return 0;
    }
    put("FAIL: samples refused or tilt or heading not valid at the end\n");
    return 1;
}
