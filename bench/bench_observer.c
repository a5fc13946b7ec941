#include <stdio.h>
int main(void) { printf("bench_observer: not written yet\n"); return 0; }
