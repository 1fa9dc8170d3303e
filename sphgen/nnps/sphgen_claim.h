/* Work sharing for the parallel loops of sphgen (the neighbour search's cut and the
 * generated passes): thread k takes its own part of the items first, a few at a time,
 * then what is left of the other parts, so a core slowed by other work hands over its
 * rest.  Each item is still done whole by one thread. */
#ifndef SPHGEN_CLAIM_H
#define SPHGEN_CLAIM_H

/* the first of n items of a shared counter, taken atomically */
static inline long sphgen_claim(long* counter, long n) {
    long first;
#ifdef _OPENMP
    #pragma omp atomic capture
#endif
    { first = *counter; *counter += n; }
    return first;
}

#endif
