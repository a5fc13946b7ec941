#include <stdio.h>
int main(void) { printf("bench_frame: not written yet\n"); return 0; }
