#include <stdio.h>
int main(void) { printf("bench_display: not written yet\n"); return 0; }
