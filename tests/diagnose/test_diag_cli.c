/* placeholder until the CLI test lands */
int main(void) { return 0; }
