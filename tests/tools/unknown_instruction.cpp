// A program valgrind 3.19 cannot run on any x86-64 host: its one instruction of its own is
// AVX-512 (EVEX-encoded), which valgrind's decoder does not know, so valgrind reports
// "Unrecognised instruction" and raises SIGILL, as it does for libhwy's RDTSCP timer probe on
// AMD Zen 5 (issue 36). Valgrind decodes every instruction itself before it runs it, so this
// happens whatever the host CPU supports. The ctest
// step_instruction_budget_skips_where_valgrind_cannot_run counts it in place of
// gmasim_step_count: scripts/performance.py must skip with the reason, not fail. It is only
// ever run under valgrind (natively it would need an AVX-512 CPU).
int main(void) {
  __asm__ volatile("vpxorq %%zmm0, %%zmm0, %%zmm0" ::: "xmm0");
  return 0;
}
