from designkit.cli import main

main()
