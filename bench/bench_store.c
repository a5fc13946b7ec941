#include <stdio.h>
int main(void) { printf("bench_store: not written yet\n"); return 0; }
