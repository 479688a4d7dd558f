/*
 * Four-quadrant arctangent (fx.h): octant folding, one ratio by 32-bit
 * division steps, and a table of atan on [0, 1] with linear interpolation.
 * Integer-only; error budget in docs/error-budget.md.
 */
#include "fx.h"

/* round(atan(i / 256) * 2^32 / (2 pi)), i = 0..256: atan on [0, 1] in
 * fx_angle_t units (atan(1) = pi/4 = 2^29 exactly). */
#define FX_ATAN_N 256u
static const uint32_t fx_atan_tab[FX_ATAN_N + 1u] = {
    0u,         2670163u,   5340245u,   8010164u,   10679838u,  13349187u,  16018129u,  18686582u,
    21354465u,  24021698u,  26688200u,  29353889u,  32018685u,  34682507u,  37345276u,  40006910u,
    42667331u,  45326458u,  47984212u,  50640513u,  53295284u,  55948444u,  58599915u,  61249621u,
    63897482u,  66543421u,  69187361u,  71829226u,  74468939u,  77106424u,  79741605u,  82374407u,
    85004756u,  87632577u,  90257796u,  92880340u,  95500135u,  98117110u,  100731191u, 103342309u,
    105950391u, 108555367u, 111157167u, 113755721u, 116350962u, 118942819u, 121531227u, 124116117u,
    126697423u, 129275078u, 131849018u, 134419178u, 136985493u, 139547900u, 142106335u, 144660738u,
    147211045u, 149757197u, 152299132u, 154836791u, 157370116u, 159899047u, 162423527u, 164943499u,
    167458907u, 169969696u, 172475810u, 174977196u, 177473799u, 179965568u, 182452450u, 184934394u,
    187411349u, 189883266u, 192350096u, 194811789u, 197268300u, 199719579u, 202165583u, 204606264u,
    207041579u, 209471483u, 211895933u, 214314887u, 216728303u, 219136141u, 221538359u, 223934919u,
    226325781u, 228710908u, 231090262u, 233463808u, 235831508u, 238193329u, 240549235u, 242899194u,
    245243172u, 247581137u, 249913059u, 252238905u, 254558647u, 256872255u, 259179700u, 261480955u,
    263775993u, 266064788u, 268347313u, 270623543u, 272893455u, 275157025u, 277414230u, 279665048u,
    281909457u, 284147437u, 286378966u, 288604026u, 290822599u, 293034664u, 295240206u, 297439207u,
    299631651u, 301817523u, 303996806u, 306169488u, 308335554u, 310494991u, 312647786u, 314793928u,
    316933406u, 319066208u, 321192324u, 323311746u, 325424463u, 327530468u, 329629752u, 331722309u,
    333808132u, 335887214u, 337959550u, 340025134u, 342083962u, 344136031u, 346181336u, 348219874u,
    350251643u, 352276640u, 354294865u, 356306316u, 358310992u, 360308894u, 362300021u, 364284375u,
    366261957u, 368232767u, 370196809u, 372154086u, 374104599u, 376048352u, 377985350u, 379915596u,
    381839095u, 383755852u, 385665872u, 387569162u, 389465727u, 391355574u, 393238710u, 395115141u,
    396984877u, 398847924u, 400704291u, 402553986u, 404397019u, 406233399u, 408063135u, 409886237u,
    411702716u, 413512582u, 415315845u, 417112518u, 418902610u, 420686135u, 422463104u, 424233528u,
    425997422u, 427754796u, 429505665u, 431250041u, 432987938u, 434719370u, 436444350u, 438162893u,
    439875013u, 441580724u, 443280042u, 444972981u, 446659557u, 448339785u, 450013680u, 451681259u,
    453342536u, 454997530u, 456646255u, 458288728u, 459924966u, 461554985u, 463178803u, 464796437u,
    466407904u, 468013221u, 469612406u, 471205476u, 472792449u, 474373344u, 475948178u, 477516969u,
    479079736u, 480636498u, 482187271u, 483732076u, 485270931u, 486803855u, 488330866u, 489851983u,
    491367227u, 492876615u, 494380167u, 495877903u, 497369841u, 498856002u, 500336404u, 501811068u,
    503280012u, 504743258u, 506200824u, 507652730u, 509098996u, 510539643u, 511974689u, 513404156u,
    514828063u, 516246430u, 517659277u, 519066625u, 520468494u, 521864904u, 523255875u, 524641427u,
    526021581u, 527396357u, 528765775u, 530129856u, 531488619u, 532842087u, 534190278u, 535533213u,
    536870912u};

/* round(n 2^24 / d) for 0 <= n <= d, 0 < d < 2^24: long division in three
 * 8-bit digits (the remainder stays below d < 2^24, so r 2^8 < 2^32). */
static uint32_t fx_ratio24(uint32_t n, uint32_t d)
{
    uint32_t r = n;
    const uint32_t q = fx_udiv_digits(0u, &r, d, 8u, 3u);
    return fx_udiv_round(q, r, d);
}

/* Number of significant bits of a non-zero value. */
static unsigned fx_bits32(uint32_t x)
{
#if defined(__GNUC__)
    return 32u - (unsigned)__builtin_clz(x);
#else
    unsigned n = 0u;
    while (x != 0u) {
        x >>= 1;
        n++;
    }
    return n;
#endif
}

fx_angle_t fx_atan2(int32_t y, int32_t x)
{
    /* Magnitudes as unsigned (|INT32_MIN| = 2^31 fits). */
    const uint32_t ax = x < 0 ? 0u - (uint32_t)x : (uint32_t)x;
    const uint32_t ay = y < 0 ? 0u - (uint32_t)y : (uint32_t)y;
    const int swap = ay > ax;
    uint32_t num = swap ? ax : ay;
    uint32_t den = swap ? ay : ax;
    if (den == 0u) {
        return 0u; /* the origin: 0 by convention */
    }
    /* Bring den below 2^24 by a rounding shift of both (den' >= 2^23 then,
     * so the ratio moves by at most 2^-23); den + 2^(s-1) <= 2^31 + 2^7. */
    const unsigned nb = fx_bits32(den);
    if (nb > 24u) {
        const unsigned s = nb - 24u;
        const uint32_t half = (uint32_t)1 << (s - 1u);
        num = (num + half) >> s;
        den = (den + half) >> s;
        if (den >= ((uint32_t)1 << 24)) { /* rounded up to 2^24 */
            num >>= 1;
            den >>= 1;
        }
    }
    const uint32_t t = fx_ratio24(num, den); /* Q24 in [0, 2^24] */
    /* Table index (t 256) and the 16-bit fraction; t = 2^24 reads the last
     * entry with a zero weight. The slope is below 2^22 per step: the
     * interpolation product fits 64 bits (one UMULL). */
    const uint32_t idx = t >> 16;
    const uint32_t frac = t & 0xFFFFu;
    const uint32_t a0 = fx_atan_tab[idx];
    const uint32_t d = idx < FX_ATAN_N ? fx_atan_tab[idx + 1u] - a0 : 0u;
    uint32_t a = a0 + (uint32_t)(((uint64_t)d * frac + 0x8000u) >> 16); /* [0, pi/4] */
    if (swap) {
        a = 0x40000000u - a; /* pi/2 - a */
    }
    if (x < 0) {
        a = 0x80000000u - a; /* pi - a */
    }
    return y < 0 ? 0u - a : a; /* unsigned wrap: -a modulo a turn */
}
