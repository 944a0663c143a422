// Shared by the sort's passes (bitonic.frag, and the fused sort's
// bitonic_pair.frag and bitonic_local.frag):
// the order of (key, record) pairs, ties broken by the record so that the
// sorted result is the faithful passes' exactly.
// Without short-circuits, so no branch.
bool pair_less(ivec4 a, ivec4 b) {
    return (int(a.x < b.x) | (int(a.x == b.x) & int(a.y < b.y))) != 0;
}

// Orders (lo, hi) ascending, or descending when !ascending, by selects.
void compare_exchange(inout ivec4 lo, inout ivec4 hi, bool ascending) {
    bool swap = pair_less(hi, lo) == ascending;
    ivec4 a = lo;
    lo = swap ? hi : lo;
    hi = swap ? a : hi;
}
