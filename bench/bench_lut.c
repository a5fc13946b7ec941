#include <stdio.h>
int main(void) { printf("bench_lut: not written yet\n"); return 0; }
