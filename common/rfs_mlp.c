/* rfs_mlp.c - the multilayer perceptron internal model (see rfs_mlp.h, paper section 5.2.2). */
#include "rfs_mlp.h"

#include <string.h>

#include "rfs_assert.h"

/* sigmoid(i / 32) in Q30 for i = 0..512 (round(2^30 / (1 + e^(-i/32)))). */
static const int32_t k_sigmoid_q30[513] = {
    536870912, 545258837, 553642669, 562018320, 570381721, 578728826,
    587055621, 595358128, 603632421, 611874625, 620080927, 628247581,
    636370916, 644447344, 652473360, 660445556, 668360618, 676215336,
    684006607, 691731441, 699386960, 706970408, 714479147, 721910665,
    729262575, 736532619, 743718666, 750818718, 757830903, 764753485,
    771584854, 778323533, 784968172, 791517550, 797970573, 804326271,
    810583795, 816742419, 822801534, 828760645, 834619371, 840377438,
    846034679, 851591031, 857046527, 862401297, 867655564, 872809637,
    877863909, 882818857, 887675030, 892433052, 897093617, 901657482,
    906125467, 910498448, 914777356, 918963172, 923056923, 927059682,
    930972558, 934796699, 938533285, 942183526, 945748661, 949229951,
    952628679, 955946146, 959183671, 962342584, 965424228, 968429952,
    971361116, 974219080, 977005208, 979720867, 982367420, 984946228,
    987458649, 989906033, 992289723, 994611057, 996871359, 999071944,
    1001214117, 1003299166, 1005328370, 1007302990, 1009224275, 1011093455,
    1012911746, 1014680345, 1016400435, 1018073178, 1019699719, 1021281184,
    1022818680, 1024313298, 1025766105, 1027178152, 1028550470, 1029884070,
    1031179945, 1032439065, 1033662384, 1034850835, 1036005333, 1037126771,
    1038216025, 1039273953, 1040301391, 1041299158, 1042268056, 1043208866,
    1044122353, 1045009262, 1045870324, 1046706249, 1047517731, 1048305448,
    1049070061, 1049812214, 1050532537, 1051231642, 1051910126, 1052568571,
    1053207546, 1053827602, 1054429278, 1055013099, 1055579574, 1056129202,
    1056662466, 1057179837, 1057681775, 1058168724, 1058641119, 1059099384,
    1059543927, 1059975150, 1060393441, 1060799177, 1061192726, 1061574446,
    1061944684, 1062303778, 1062652055, 1062989834, 1063317427, 1063635133,
    1063943245, 1064242049, 1064531819, 1064812825, 1065085327, 1065349577,
    1065605823, 1065854303, 1066095248, 1066328884, 1066555430, 1066775098,
    1066988093, 1067194616, 1067394862, 1067589019, 1067777269, 1067959791,
    1068136757, 1068308334, 1068474685, 1068635967, 1068792334, 1068943933,
    1069090909, 1069233402, 1069371547, 1069505476, 1069635316, 1069761192,
    1069883223, 1070001526, 1070116214, 1070227397, 1070335182, 1070439671,
    1070540964, 1070639160, 1070734352, 1070826631, 1070916086, 1071002803,
    1071086865, 1071168354, 1071247347, 1071323921, 1071398150, 1071470105,
    1071539855, 1071607468, 1071673008, 1071736540, 1071798125, 1071857821,
    1071915687, 1071971779, 1072026150, 1072078854, 1072129942, 1072179462,
    1072227463, 1072273991, 1072319092, 1072362809, 1072405184, 1072446258,
    1072486072, 1072524664, 1072562070, 1072598329, 1072633474, 1072667541,
    1072700561, 1072732567, 1072763590, 1072793661, 1072822808, 1072851059,
    1072878443, 1072904986, 1072930713, 1072955650, 1072979821, 1073003249,
    1073025958, 1073047968, 1073069303, 1073089982, 1073110025, 1073129452,
    1073148282, 1073166534, 1073184225, 1073201372, 1073217991, 1073234100,
    1073249714, 1073264848, 1073279517, 1073293735, 1073307515, 1073320872,
    1073333819, 1073346367, 1073358530, 1073370318, 1073381745, 1073392819,
    1073403554, 1073413958, 1073424042, 1073433817, 1073443291, 1073452473,
    1073461373, 1073469999, 1073478361, 1073486465, 1073494319, 1073501933,
    1073509312, 1073516464, 1073523396, 1073530115, 1073536627, 1073542939,
    1073549057, 1073554987, 1073560734, 1073566305, 1073571704, 1073576938,
    1073582010, 1073586926, 1073591691, 1073596310, 1073600786, 1073605125,
    1073609330, 1073613406, 1073617357, 1073621186, 1073624897, 1073628494,
    1073631980, 1073635360, 1073638635, 1073641809, 1073644886, 1073647868,
    1073650759, 1073653560, 1073656276, 1073658908, 1073661458, 1073663931,
    1073666327, 1073668650, 1073670901, 1073673083, 1073675198, 1073677248,
    1073679234, 1073681160, 1073683026, 1073684835, 1073686588, 1073688288,
    1073689935, 1073691531, 1073693078, 1073694578, 1073696032, 1073697440,
    1073698806, 1073700129, 1073701412, 1073702655, 1073703861, 1073705028,
    1073706161, 1073707258, 1073708321, 1073709352, 1073710351, 1073711319,
    1073712258, 1073713167, 1073714049, 1073714904, 1073715732, 1073716535,
    1073717313, 1073718067, 1073718798, 1073719506, 1073720193, 1073720858,
    1073721503, 1073722128, 1073722734, 1073723322, 1073723891, 1073724443,
    1073724977, 1073725496, 1073725998, 1073726485, 1073726957, 1073727414,
    1073727858, 1073728287, 1073728704, 1073729108, 1073729499, 1073729878,
    1073730246, 1073730602, 1073730947, 1073731282, 1073731606, 1073731920,
    1073732225, 1073732520, 1073732807, 1073733084, 1073733353, 1073733614,
    1073733866, 1073734111, 1073734348, 1073734578, 1073734801, 1073735017,
    1073735227, 1073735430, 1073735626, 1073735817, 1073736002, 1073736181,
    1073736355, 1073736523, 1073736686, 1073736844, 1073736997, 1073737146,
    1073737290, 1073737429, 1073737564, 1073737696, 1073737823, 1073737946,
    1073738065, 1073738181, 1073738293, 1073738401, 1073738507, 1073738609,
    1073738708, 1073738804, 1073738896, 1073738987, 1073739074, 1073739158,
    1073739240, 1073739320, 1073739397, 1073739472, 1073739544, 1073739614,
    1073739682, 1073739748, 1073739812, 1073739874, 1073739934, 1073739992,
    1073740048, 1073740103, 1073740156, 1073740207, 1073740257, 1073740305,
    1073740352, 1073740397, 1073740441, 1073740484, 1073740525, 1073740565,
    1073740604, 1073740641, 1073740678, 1073740713, 1073740747, 1073740780,
    1073740812, 1073740843, 1073740874, 1073740903, 1073740931, 1073740959,
    1073740985, 1073741011, 1073741036, 1073741060, 1073741084, 1073741107,
    1073741129, 1073741150, 1073741171, 1073741191, 1073741210, 1073741229,
    1073741248, 1073741265, 1073741282, 1073741299, 1073741315, 1073741331,
    1073741346, 1073741361, 1073741375, 1073741389, 1073741402, 1073741415,
    1073741428, 1073741440, 1073741452, 1073741463, 1073741474, 1073741485,
    1073741496, 1073741506, 1073741515, 1073741525, 1073741534, 1073741543,
    1073741552, 1073741560, 1073741568, 1073741576, 1073741584, 1073741591,
    1073741598, 1073741605, 1073741612, 1073741618, 1073741625, 1073741631,
    1073741637, 1073741643, 1073741648, 1073741654, 1073741659, 1073741664,
    1073741669, 1073741674, 1073741678, 1073741683, 1073741687, 1073741691,
    1073741695, 1073741699, 1073741703,
};

/* Standardised inputs are clamped to +-256 (Q16.16 +-2^24) so that a Q8.24 weight times
 * an input (< 2^55) and the sum of three such terms fit int64. */
#define MLP_IN_LIMIT_Q16 ((int32_t)1 << 24)
/* Output errors are clamped to +-512 standardised units (Q16.16 2^25) so that
 * rate * error * v * sigmoid' (< 2^33 * 2^29) fits int64. */
#define MLP_ERR_LIMIT_Q16 ((int32_t)1 << 25)
/* Standard deviations below 1/128 of a unit (Q16.16 512) count as zero, because their
 * inverse would not fit Q8.24; scikit-learn then scales by 1 (metres, target units). */
#define MLP_MIN_STD_Q16 512

/* v / 2^s rounded to nearest (ties up); arithmetic shift. */
static int64_t rshr(int64_t v, unsigned s)
{
    return (v + ((int64_t)1 << (s - 1u))) >> s;
}

static int32_t clamp32(int32_t v, int32_t lim)
{
    return v > lim ? lim : (v < -lim ? -lim : v);
}

rfs_q16_t rfs_mlp_sigmoid(rfs_q16_t a)
{
    /* Work on |a|; sigmoid(-a) = 1 - sigmoid(a). */
    uint32_t u = a < 0 ? (uint32_t)0 - (uint32_t)a : (uint32_t)a;
    int64_t s_q30;
    if (u >= ((uint32_t)16 << 16)) {
        s_q30 = (int64_t)1 << 30;
    } else {
        uint32_t i = u >> 11;          /* table step 1/32 = 2^11 in Q16 */
        int64_t f = (int64_t)(u & 0x7FFu);
        int64_t lo = k_sigmoid_q30[i];
        int64_t hi = k_sigmoid_q30[i + 1u];
        s_q30 = lo + rshr((hi - lo) * f, 11);
    }
    if (a < 0) {
        s_q30 = ((int64_t)1 << 30) - s_q30;
    }
    return (rfs_q16_t)rshr(s_q30, 14);
}

rfs_mlp_cfg_t rfs_mlp_cfg_default(void)
{
    rfs_mlp_cfg_t c = {
        .hidden = 100u,
        .epochs = 3u,
        .rate_q30 = 10737418,     /* 0.01 * 2^30 */
        .momentum_q30 = 107374182, /* 0.1 * 2^30 */
        .max_samples = 10000u,
    };
    return c;
}

int rfs_mlp_init(rfs_mlp_t *m, const rfs_mlp_cfg_t *cfg)
{
    RFS_ASSERT(m != NULL && cfg != NULL);
    if (cfg->hidden == 0u || cfg->hidden > RFS_MLP_MAX_HIDDEN || cfg->epochs == 0u ||
        cfg->rate_q30 <= 0 || cfg->rate_q30 > ((int32_t)1 << 30) || cfg->momentum_q30 < 0 ||
        cfg->momentum_q30 >= ((int32_t)1 << 30) || cfg->max_samples == 0u ||
        cfg->max_samples > RFS_MLP_MAX_SAMPLES) {
        return -1;
    }
    memset(m, 0, sizeof(*m));
    m->cfg = *cfg;
    return 0;
}

/* Mean (Q16.16 of the raw unit) and 1/std (Q8.24 per raw unit) of n integer values
 * given their sum s1 and sum of squares s2.
 * Scaling and overflow: |values| <= 2^15 and n <= 10,000, so |s1| < 2^29 and
 * s2 < 2^44; n * s2 - s1^2 < 2^58 in int64; the variance in Q32.32 is an exact 128-bit
 * quotient (< 2^62), its integer square root the std in Q16.16; 2^40 / std is Q8.24. */
static void moments(int64_t s1, int64_t s2, uint16_t n, int32_t unit_inv_q24,
                    int32_t *mean_q16, int32_t *inv_q24, int32_t *std_q16)
{
    *mean_q16 = rfs_sat32(rfs_sdiv64_round(s1 * 65536, (int64_t)n));
    int64_t num = (int64_t)n * s2 - s1 * s1;
    if (num < 0) {
        num = 0;
    }
    int64_t var_q32 = rfs_i128_div_shift(rfs_i128_mul(num, 1), rfs_i128_mul(n, n), 32);
    uint32_t sd = rfs_isqrt64((uint64_t)var_q32);
    if (sd < MLP_MIN_STD_Q16) {
        *inv_q24 = unit_inv_q24;
        *std_q16 = 0;
        return;
    }
    *inv_q24 = rfs_sat32((int64_t)rfs_udiv64(((uint64_t)1 << 40) + (sd >> 1), sd));
    *std_q16 = (int32_t)sd;
}

/* (raw - mean) / std as Q16.16, clamped to +-256.
 * Scaling and overflow: raw and mean Q16.16 of the same unit; their difference is
 * clamped to int32 so that times inv (Q8.24, < 2^31) it stays below 2^62; >> 24. */
static int32_t standardise(int64_t raw_q16, int32_t mean_q16, int32_t inv_q24)
{
    int64_t d = raw_q16 - mean_q16;
    d = d > INT32_MAX ? INT32_MAX : (d < -INT32_MAX ? -INT32_MAX : d);
    return clamp32(rfs_sat32(rshr(d * inv_q24, 24)), MLP_IN_LIMIT_Q16);
}

/* One Q8.24 weight of unit variance from two rng draws (Irwin-Hall of four 16-bit
 * uniforms). Scaling: the sum of four Q16 uniforms minus 2.0 is Q16; times sqrt(3) in
 * Q16.16 (113512) is Q32, >> 8 is Q24 (|w| <= 2 sqrt(3)). */
static int32_t draw_weight(rfs_rng_t *rng)
{
    uint32_t a = rfs_rng_u32(rng);
    uint32_t b = rfs_rng_u32(rng);
    int64_t s = (int64_t)(a & 0xFFFFu) + (a >> 16) + (b & 0xFFFFu) + (b >> 16);
    return (int32_t)rshr((s - 131072) * 113512, 8);
}

/* Forward pass on standardised inputs; h receives the hidden activations (Q16.16)
 * when not NULL. Returns the standardised output, Q16.16.
 * Scaling and overflow: w (Q8.24) x input (Q16.16, |.| <= 2^24) < 2^55, plus the
 * bias x 2^16, is the pre-activation in Q40 (int64) -> Q16.16 for the sigmoid;
 * v (Q8.24) x h (Q16.16, <= 2^16) < 2^47, summed over <= 100 units in Q40 -> Q16.16. */
static int32_t forward(const rfs_mlp_t *m, int32_t xs, int32_t ys, int32_t *h)
{
    int64_t acc = (int64_t)m->c_q24 * 65536;
    for (uint16_t j = 0u; j < m->cfg.hidden; ++j) {
        int64_t a = (int64_t)m->w_q24[j][0] * xs + (int64_t)m->w_q24[j][1] * ys +
                    (int64_t)m->b_q24[j] * 65536;
        int32_t hj = rfs_mlp_sigmoid(rfs_sat32(rshr(a, 24)));
        if (h != NULL) {
            h[j] = hj;
        }
        acc += (int64_t)m->v_q24[j] * hj;
    }
    return rfs_sat32(rshr(acc, 24));
}

/* m = momentum * m + step; w += m; both saturate to Q8.24.
 * Scaling: momentum Q2.30 x m Q8.24 = Q54 (< 2^61) >> 30 = Q24. */
static void descend(int32_t *w, int32_t *mom, int64_t step_q24, int32_t momentum_q30)
{
    int64_t mv = rshr((int64_t)momentum_q30 * *mom, 30) + step_q24;
    *mom = rfs_sat32(mv);
    *w = rfs_sat32((int64_t)*w + *mom);
}

/* One online backpropagation step on one sample (PyBrain BackpropTrainer semantics: all
 * derivatives from the weights before the step, then every weight moves).
 * Scaling and overflow: error e Q16.16 clamped to +-2^25; rate (Q2.30 <= 2^30) x e
 * >> 22 is rate*e in Q24 (< 2^33); times h (Q16) >> 16 is the output weight step Q24;
 * v (Q24) x h(1-h) (Q16, <= 2^14) >> 16 is Q24 (< 2^29), times rate*e (< 2^62) >> 24 is
 * the hidden delta in Q24 (< 2^38); times an input (Q16, <= 2^24, < 2^62) >> 16 is Q24. */
static void train_one(rfs_mlp_t *m, const rfs_sample_t *s)
{
    int32_t h[RFS_MLP_MAX_HIDDEN];
    int32_t xs = standardise((int64_t)s->x_cm * 65536, m->mean_x_q16, m->inv_sx_q24);
    int32_t ys = standardise((int64_t)s->y_cm * 65536, m->mean_y_q16, m->inv_sy_q24);
    int32_t t = standardise((int64_t)s->v_q6 * 65536, m->mean_v_q16, m->inv_sv_q24);
    int32_t y = forward(m, xs, ys, h);
    int32_t e = clamp32(rfs_sat32((int64_t)t - y), MLP_ERR_LIMIT_Q16);
    int64_t le_q24 = rshr((int64_t)m->cfg.rate_q30 * e, 22);
    int32_t mom = m->cfg.momentum_q30;
    for (uint16_t j = 0u; j < m->cfg.hidden; ++j) {
        int64_t g_q16 = rshr((int64_t)h[j] * (65536 - h[j]), 16);
        int64_t vg_q24 = rshr((int64_t)m->v_q24[j] * g_q16, 16);
        int64_t ld_q24 = rshr(le_q24 * vg_q24, 24);
        descend(&m->v_q24[j], &m->mv_q24[j], rshr(le_q24 * h[j], 16), mom);
        descend(&m->w_q24[j][0], &m->mw_q24[j][0], rshr(ld_q24 * xs, 16), mom);
        descend(&m->w_q24[j][1], &m->mw_q24[j][1], rshr(ld_q24 * ys, 16), mom);
        descend(&m->b_q24[j], &m->mb_q24[j], ld_q24, mom);
    }
    descend(&m->c_q24, &m->mc_q24, le_q24, mom);
}

/* Standardisation constants and fresh weights: the start of a fit. */
static void start_fit(rfs_mlp_t *m, const rfs_sample_t *samples, uint16_t n, rfs_rng_t *rng)
{
    int64_t sx = 0, sxx = 0, sy = 0, syy = 0, sv = 0, svv = 0;
    for (uint16_t i = 0u; i < n; ++i) {
        int64_t x = samples[i].x_cm, y = samples[i].y_cm, v = samples[i].v_q6;
        sx += x;
        sxx += x * x;
        sy += y;
        syy += y * y;
        sv += v;
        svv += v * v;
    }
    int32_t sd_unused, sd_v;
    /* Constant features scale by 1 per metre (1/100 per cm), a constant target by 1 per
     * target unit (1/64 per Q9.6 unit), as StandardScaler does. */
    moments(sx, sxx, n, (int32_t)((1 << 24) / 100), &m->mean_x_q16, &m->inv_sx_q24, &sd_unused);
    moments(sy, syy, n, (int32_t)((1 << 24) / 100), &m->mean_y_q16, &m->inv_sy_q24, &sd_unused);
    moments(sv, svv, n, (int32_t)(1 << 18), &m->mean_v_q16, &m->inv_sv_q24, &sd_v);
    m->out_mean = (rfs_q16_t)rshr(m->mean_v_q16, 6);
    m->out_std = sd_v == 0 ? RFS_Q16_ONE : (rfs_q16_t)rshr(sd_v, 6);

    for (uint16_t j = 0u; j < m->cfg.hidden; ++j) {
        m->w_q24[j][0] = draw_weight(rng);
        m->w_q24[j][1] = draw_weight(rng);
        m->b_q24[j] = draw_weight(rng);
    }
    for (uint16_t j = 0u; j < m->cfg.hidden; ++j) {
        m->v_q24[j] = draw_weight(rng);
    }
    m->c_q24 = draw_weight(rng);
    memset(m->mw_q24, 0, sizeof(m->mw_q24));
    memset(m->mb_q24, 0, sizeof(m->mb_q24));
    memset(m->mv_q24, 0, sizeof(m->mv_q24));
    m->mc_q24 = 0;
    uint8_t h = 1u;
    while (((uint32_t)1 << (2u * h)) < n) {
        ++h;
    }
    m->half_bits = h;
    m->fit_n = n;
    m->pos = 0u;
    m->epoch = 0u;
}

/* The round function of the Feistel network (see rfs_mlp.h). */
static uint32_t feistel_f(uint32_t k, uint32_t r, uint32_t mask)
{
    uint32_t x = (k ^ r) * 0x9E3779B1u;
    x ^= x >> 15;
    x *= 0x85EBCA6Bu;
    x ^= x >> 13;
    return x & mask;
}

/* Position p of the epoch -> sample index, a bijection of [0, fit_n). The Feistel
 * network permutes [0, 4^h); cycle walking maps it back into [0, fit_n). */
static uint16_t permute(const rfs_mlp_t *m, uint16_t p)
{
    uint32_t h = m->half_bits, mask = ((uint32_t)1 << h) - 1u, i = p;
    do {
        uint32_t l = i >> h, r = i & mask;
        for (unsigned k = 0u; k < 4u; ++k) {
            uint32_t t = l ^ feistel_f(m->key[k], r, mask);
            l = r;
            r = t;
        }
        i = (l << h) | r;
    } while (i >= m->fit_n);
    return (uint16_t)i;
}

static void mlp_reset(void *self)
{
    rfs_mlp_t *m = self;
    m->valid = false;
    m->fitting = false;
}

static rfs_fit_result_t mlp_fit(void *self, const rfs_model_fit_in_t *in, uint32_t budget,
                                rfs_rng_t *rng)
{
    rfs_mlp_t *m = self;
    RFS_ASSERT(m != NULL && in != NULL && rng != NULL);
    m->updates = 0u;
    uint16_t n = in->n < m->cfg.max_samples ? in->n : m->cfg.max_samples;
    if (!m->fitting || n < m->fit_n) {
        m->valid = false;
        m->fitting = false;
        if (n == 0u || in->samples == NULL) {
            return RFS_FIT_FAILED;
        }
        start_fit(m, in->samples, n, rng);
        m->fitting = true;
    }
    for (;;) {
        if (m->pos == m->fit_n) {
            m->pos = 0u;
            m->epoch++;
        }
        if (m->epoch >= m->cfg.epochs) {
            break;
        }
        if (budget != 0u && m->updates >= budget) {
            return RFS_FIT_MORE;
        }
        if (m->pos == 0u) {
            /* A fresh order every epoch, as PyBrain reshuffles at every epoch. */
            for (unsigned r = 0u; r < 4u; ++r) {
                m->key[r] = rfs_rng_u32(rng);
            }
        }
        train_one(m, &in->samples[permute(m, m->pos)]);
        m->pos++;
        m->updates++;
    }
    m->fitting = false;
    m->valid = true;
    return RFS_FIT_DONE;
}

static bool mlp_predict(const void *self, rfs_q16_t x, rfs_q16_t y, rfs_q16_t *value)
{
    const rfs_mlp_t *m = self;
    RFS_ASSERT(m != NULL && value != NULL);
    if (!m->valid) {
        return false;
    }
    int32_t xs = standardise((int64_t)x * 100, m->mean_x_q16, m->inv_sx_q24);
    int32_t ys = standardise((int64_t)y * 100, m->mean_y_q16, m->inv_sy_q24);
    int32_t o = forward(m, xs, ys, NULL);
    *value = rfs_q16_add(m->out_mean, rfs_q16_mul(o, m->out_std));
    return true;
}

/* --- Upper bound over a box (the grid search's branch and bound, rfs_gridmax.h) ---- */

/* The bound follows mlp_predict() step by step. Every step before the output sum is
 * monotone (standardise, the pre-activation's rounding and saturation, the sigmoid: its
 * monotonicity is tested exhaustively), and so is every step after it (rshr, rfs_sat32,
 * rfs_q16_mul by out_std > 0, rfs_q16_add), so a true upper bound of forward()'s int64
 * output sum `acc` (Q40) gives one of the prediction, bit for bit. Two bounds of acc, the
 * smaller is used:
 * - interval: each pre-activation p_j is linear in the standardised inputs, so its range
 *   [l_j, u_j] over the box is exact from the corners; h_j = S(p_j) is in [S(l_j), S(u_j)]
 *   and acc <= c + sum_j v_j S(u_j or l_j), exact. Loose on large boxes: every unit takes
 *   its best end at once (tens of dB over a 3.75 m tile).
 * - linear relaxation (a first-order Taylor bound, as neural-network verifiers use): for
 *   a unit whose range is inside +-16, with m_j the middle of [l_j, u_j] and
 *   R_j = max |p - m_j|, the exact logistic sigma gives (Lagrange remainder)
 *     v S(p) <= v S(m) + v sigma'(m) (p - m) + |v| (2 E + C R^2 / 2)
 *   (in LSB of Q16), E the table's error against sigma (<= 1.27 LSB, tested; 2 charged),
 *   C a bound of sigma'' of the sign that hurts over [l, u] (v > 0: the convex side p < 0
 *   only; v < 0: the concave side p > 0 only). The slope used, G = v k with
 *   k = S(m) (1 - S(m)) rounded (k within 3 LSB of 2^16 sigma'(m)), is within
 *   3 |v| / 2^16 + 1/2 (Q24) of v sigma'(m), charged times R.
 *   Then p = A / 2^24 + delta (|delta| <= 1/2, charged |G| / 2) and A is linear in the
 *   inputs, so sum_j G_j (p_j - m_j) is linear in (xs, ys) and is largest at a corner: the
 *   units' slopes cancel where the network's own gradient is small, which the interval
 *   bound cannot see. A unit takes the relaxation only when its charge is below its
 *   interval charge v (S(end) - S(m)). Every product is rounded up (mul_ceil24).
 * The remainder C R^2 / 2 dominates what is left (about 6 dB over a 3.75 m tile of a
 * paper-configuration fit, 0.3 dB over 1 m; docs/MODELS.md). Cost: two sigmoids and about
 * ten 64-bit products per unit, about 5 predictions' work. */

/* |S(p) - 2^16 sigmoid(p / 2^16)| in LSB, all p (tested max 1.27). */
#define MLP_TAB_ERR_LSB 2
/* max |sigmoid''| = sqrt(3) / 18 = 0.0962250, Q16 rounded up. */
#define MLP_CURV_MAX_Q16 6307
/* |sigmoid''(t)| rises on [0, 1.3169579] (86308.15 in Q16) and falls beyond it. */
#define MLP_CURV_PEAK_LO_Q16 86300
#define MLP_CURV_PEAK_HI_Q16 86320
/* Pre-activation ranges inside (-16, 16) (Q16) may take the linear relaxation. */
#define MLP_RELAX_LIMIT_Q16 ((int32_t)1 << 20)
/* The box is split into 2^s x 2^s parts, each bounded, the largest taken. 0: a 2 x 2 split
 * quarters the remainder but costs four bounds; on the Cortex-M4 bench the grid search
 * then takes 17.7 M instructions instead of 15.1 M and the deciding period misses 200 ms
 * (docs/PERFORMANCE.md, "Models"). */
#define MLP_BOUND_SPLIT_LOG2 0u

/* Upper bound of |sigmoid''(t)| from s = S(t) (either half), Q16.
 * Scaling and overflow: s (2^16 - s) <= 2^30 times |2 s - 2^16| <= 2^16 is < 2^46 in
 * int64; >> 32 is f(s) = s (1 - s) |1 - 2 s| in Q16, floored (+1). |f'| <= 1 on each half
 * and S stays on sigma's half, so the table's error moves f by at most MLP_TAB_ERR_LSB. */
static int64_t curv_from_s(int64_t s)
{
    int64_t d = 2 * s - 65536;
    return ((s * (65536 - s) * (d < 0 ? -d : d)) >> 32) + 1 + MLP_TAB_ERR_LSB;
}

/* ceil(g e / 2^24), exact. Scaling and overflow: |g| < 2^31, |e| < 2^55; e = eh 2^24 + el
 * with 0 <= el < 2^24, so g eh < 2^62 and g el < 2^55 fit int64 (no 128-bit product). */
static int64_t mul_ceil24(int64_t g, int64_t e)
{
    int64_t eh = e >> 24;
    int64_t el = e - eh * ((int64_t)1 << 24);
    return g * eh + ((g * el + (((int64_t)1 << 24) - 1)) >> 24);
}

/* Upper bound of forward()'s acc (Q40) over standardised inputs [xa, xb] x [ya, yb].
 * Scaling and overflow: |xs|, |ys| <= 2^24 (Q16), weights < 2^31 (Q24): pre-activations
 * |A| < 3 x 2^55 (Q40) as in forward(); v S < 2^47, the interval sum < 2^54. A relaxed unit
 * has u - l < 2^21, so R <= 2^20, A's range < 2^46 and |A - m 2^24| < 2^46; C < 2^13,
 * C R^2 < 2^53 >> 25 is the remainder in Q8 of an LSB (< 2^29), times |v| < 2^60; the slope
 * charge (3 |v| + 2^15) R < 2^54; k <= 2^14 (Q16), G = v k >> 16 < 2^29 (Q24). Each of the
 * six terms of a relaxed unit is below 2^53 in Q40, so 100 units' sums stay below 2^63. */
static int64_t box_acc(const rfs_mlp_t *m, int64_t xa, int64_t xb, int64_t ya, int64_t yb)
{
    int64_t xc = xa + ((xb - xa) >> 1), yc = ya + ((yb - ya) >> 1);
    int64_t iv = (int64_t)m->c_q24 * 65536;     /* interval bound, Q40 */
    int64_t rb = iv;                            /* relaxed bound, Q40 */
    int64_t lxa = 0, lxb = 0, lya = 0, lyb = 0; /* its linear part at either end, Q40 */
    for (uint16_t j = 0u; j < m->cfg.hidden; ++j) {
        int64_t w0 = m->w_q24[j][0], w1 = m->w_q24[j][1], b = (int64_t)m->b_q24[j] * 65536;
        int64_t alo = (w0 >= 0 ? w0 * xa : w0 * xb) + (w1 >= 0 ? w1 * ya : w1 * yb) + b;
        int64_t ahi = (w0 >= 0 ? w0 * xb : w0 * xa) + (w1 >= 0 ? w1 * yb : w1 * ya) + b;
        int32_t l = rfs_sat32(rshr(alo, 24)), u = rfs_sat32(rshr(ahi, 24));
        int64_t v = m->v_q24[j];
        int64_t hub = rfs_mlp_sigmoid(v >= 0 ? u : l);
        iv += v * hub;
        if (l <= -MLP_RELAX_LIMIT_Q16 || u >= MLP_RELAX_LIMIT_Q16) {
            rb += v * hub;
            continue;
        }
        int32_t mid = l + ((u - l) >> 1);
        int64_t r = (u - mid) > (mid - l) ? (u - mid) : (mid - l);
        int64_t sm = rfs_mlp_sigmoid(mid);
        /* |t| range [a, e] of the side that hurts; |sigma''(t)| <= |t| / 8 (sigma' <= 1/4,
         * |1 - 2 sigma| = tanh(|t| / 2) <= |t| / 2), rises to its peak, then falls. */
        int64_t curv = 0, a = 0, e = -1;
        if (v >= 0 && l < 0) {
            a = u < 0 ? -u : 0;
            e = -l;
        } else if (v < 0 && u > 0) {
            a = l > 0 ? l : 0;
            e = u;
        }
        if (e >= 0) {
            curv = e <= MLP_CURV_PEAK_LO_Q16 ? (e >> 3) + 1
                   : (a >= MLP_CURV_PEAK_HI_Q16 ? curv_from_s(hub) : MLP_CURV_MAX_Q16);
            curv = curv < MLP_CURV_MAX_Q16 ? curv : MLP_CURV_MAX_Q16;
        }
        int64_t k = (sm * (65536 - sm) + 32768) >> 16;
        int64_t g = rshr(v * k, 16);
        int64_t av = v < 0 ? -v : v, ag = g < 0 ? -g : g;
        int64_t e8 = ((curv * r * r + (((int64_t)1 << 25) - 1)) >> 25) +
                     2 * MLP_TAB_ERR_LSB * 256;
        int64_t charge = ((av * e8 + 255) >> 8) + (((3 * av + 32768) * r + 65535) >> 16) +
                         ((ag + 1) >> 1);
        if (charge >= v * (hub - sm)) {
            rb += v * hub;
            continue;
        }
        rb += v * sm + charge + mul_ceil24(g, w0 * xc + w1 * yc + b - (int64_t)mid * (1 << 24));
        lxa += mul_ceil24(g, w0 * (xa - xc));
        lxb += mul_ceil24(g, w0 * (xb - xc));
        lya += mul_ceil24(g, w1 * (ya - yc));
        lyb += mul_ceil24(g, w1 * (yb - yc));
    }
    rb += (lxa > lxb ? lxa : lxb) + (lya > lyb ? lya : lyb);
    return rb < iv ? rb : iv;
}

/* The bound op (rfs_model.h): the largest box_acc() of the box's parts, through the
 * output steps of mlp_predict(). A single point gets its prediction exactly. */
static bool mlp_bound(const void *self, rfs_q16_t x0, rfs_q16_t y0, rfs_q16_t x1,
                      rfs_q16_t y1, rfs_q16_t *ub)
{
    const rfs_mlp_t *m = self;
    RFS_ASSERT(m != NULL && ub != NULL && x0 <= x1 && y0 <= y1);
    if (!m->valid) {
        return false;
    }
    int64_t xa = standardise((int64_t)x0 * 100, m->mean_x_q16, m->inv_sx_q24);
    int64_t xb = standardise((int64_t)x1 * 100, m->mean_x_q16, m->inv_sx_q24);
    int64_t ya = standardise((int64_t)y0 * 100, m->mean_y_q16, m->inv_sy_q24);
    int64_t yb = standardise((int64_t)y1 * 100, m->mean_y_q16, m->inv_sy_q24);
    int64_t acc = INT64_MIN;
    /* Split only a box of some extent (with MLP_BOUND_SPLIT_LOG2 > 0). */
    const unsigned split = MLP_BOUND_SPLIT_LOG2;
    unsigned sx = xb > xa ? split : 0u;
    unsigned sy = yb > ya ? split : 0u;
    for (int64_t i = 0; i < ((int64_t)1 << sx); ++i) {
        for (int64_t k = 0; k < ((int64_t)1 << sy); ++k) {
            int64_t a = box_acc(m, xa + (((xb - xa) * i) >> sx),
                                xa + (((xb - xa) * (i + 1)) >> sx),
                                ya + (((yb - ya) * k) >> sy), ya + (((yb - ya) * (k + 1)) >> sy));
            acc = a > acc ? a : acc;
        }
    }
    int32_t o = rfs_sat32(rshr(acc, 24));
    *ub = rfs_q16_add(m->out_mean, rfs_q16_mul(o, m->out_std));
    return true;
}

const rfs_model_ops_t rfs_mlp_ops = {
    .name = "mlp",
    .reset = mlp_reset,
    .fit = mlp_fit,
    .predict = mlp_predict,
    .argmax = NULL,
    .bound = mlp_bound,
};

rfs_model_t rfs_mlp_model(rfs_mlp_t *m)
{
    rfs_model_t mod = {.ops = &rfs_mlp_ops, .self = m};
    return mod;
}
